#include "rdm/service/client.h"

#include <algorithm>
#include <chrono>
#include <thread>

#include <httplib.h>
#include <netdb.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace rdm {

using nlohmann::json;

std::string HttpReply::header(const std::string& name) const {
  auto it = headers.find(name);
  return it == headers.end() ? std::string() : it->second;
}

std::string describeHttpError(const HttpReply& reply) {
  std::string detail = reply.body;
  json j = json::parse(reply.body, nullptr, false);
  if (!j.is_discarded() && j.is_object() && j.contains("detail") && j["detail"].is_string())
    detail = j["detail"];
  return "HTTP " + std::to_string(reply.status) + ": " + detail;
}

namespace {

// The OS's reason a TCP connection to host:port of `url` fails now; empty when it succeeds.
std::string connectFailure(const std::string& url) {
  std::string rest = url.substr(url.find("//") == std::string::npos ? 0 : url.find("//") + 2);
  rest = rest.substr(0, rest.find('/'));
  const size_t colon = rest.rfind(':');
  const std::string host = colon == std::string::npos ? rest : rest.substr(0, colon);
  const std::string port = colon == std::string::npos ? "80" : rest.substr(colon + 1);
  addrinfo hints{};
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  if (int e = getaddrinfo(host.c_str(), port.c_str(), &hints, &found); e != 0)
    return "cannot resolve '" + host + "': " + gai_strerror(e);
  std::string reason = "no address to connect to";
  for (addrinfo* a = found; a; a = a->ai_next) {
    const int fd = ::socket(a->ai_family, a->ai_socktype, a->ai_protocol);
    if (fd < 0) continue;
    const bool ok = ::connect(fd, a->ai_addr, a->ai_addrlen) == 0;
    reason = ok ? "" : std::strerror(errno);
    ::close(fd);
    if (ok) break;
  }
  freeaddrinfo(found);
  return reason;
}

// httplib names a transport failure in one word; this says what happened, for a connection
// failure with the operating system's reason (found by connecting once more).
std::string transportCause(httplib::Error e, const std::string& url) {
  switch (e) {
    case httplib::Error::Connection:
    case httplib::Error::ConnectionTimeout: {
      const std::string reason = connectFailure(url);
      return reason.empty() ? "no answer within the connection timeout" : reason;
    }
    case httplib::Error::Read:
      return "the connection broke while reading the reply";
    case httplib::Error::Write:
      return "the connection broke while sending the request";
    default:
      return "transport error '" + httplib::to_string(e) + "'";
  }
}

StatusCode codeOfHttp(int status) {
  if (status == 400) return StatusCode::kMalformed;
  if (status == 413) return StatusCode::kTooLarge;
  if (status == 429) return StatusCode::kBusy;
  if (status == 404) return StatusCode::kNotFound;
  if (status == 409 || status == 412) return StatusCode::kConflict;
  if (status == 507) return StatusCode::kNoSpace;
  if (status >= 400 && status < 500) return StatusCode::kInvalidInput;
  return StatusCode::kInternal;
}

}  // namespace

Status httpErrorStatus(const HttpReply& reply) {
  json j = json::parse(reply.body, nullptr, false);
  std::string field;
  if (!j.is_discarded() && j.is_object() && j.contains("field") && j["field"].is_string())
    field = j["field"];
  return Status::error(codeOfHttp(reply.status), describeHttpError(reply), field);
}

struct BakeClient::Impl {
  std::string url;
  httplib::Client http;
  httplib::Headers auth;
  explicit Impl(const std::string& u) : url(u), http(u) {}

  Expected<HttpReply> reply(const httplib::Result& r, const std::string& what) {
    if (!r)
      return Status::error(StatusCode::kIo, "cannot reach the server at " + url + ": " +
                                                transportCause(r.error(), url) + " (" + what +
                                                "). Is `rdm serve` running there?");
    HttpReply out;
    out.status = r->status;
    out.body = r->body;
    for (const auto& [k, v] : r->headers) out.headers.emplace(k, v);
    return out;
  }
};

BakeClient::BakeClient(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
BakeClient::~BakeClient() = default;

Expected<std::unique_ptr<BakeClient>> BakeClient::connect(const std::string& given_url,
                                                          const std::string& token) {
  if (given_url.rfind("http://", 0) != 0)
    return Status::error("server URL must start with http:// (got '" + given_url + "')");
  // "http://HOST:PORT/" names the server "http://HOST:PORT" does; httplib takes no path.
  std::string url = given_url;
  constexpr size_t kSchemeLength = 7;  // "http://"
  while (url.size() > kSchemeLength && url.back() == '/') url.pop_back();
  if (url.find('/', kSchemeLength) != std::string::npos)
    return Status::error("server URL is http://HOST:PORT, without a path (got '" + given_url +
                         "')");
  auto impl = std::make_unique<Impl>(url);
  if (!impl->http.is_valid()) return Status::error("invalid server URL '" + url + "'");
  impl->http.set_connection_timeout(5, 0);
  impl->http.set_read_timeout(60, 0);
  impl->http.set_write_timeout(60, 0);
  if (!token.empty()) impl->auth.emplace("Authorization", "Bearer " + token);
  return std::unique_ptr<BakeClient>(new BakeClient(std::move(impl)));
}

Expected<HttpReply> BakeClient::get(const std::string& path,
                                    const std::map<std::string, std::string>& headers) {
  httplib::Headers h = impl_->auth;
  for (const auto& [k, v] : headers) h.emplace(k, v);
  return impl_->reply(impl_->http.Get(path.c_str(), h), "GET " + path);
}

Expected<HttpReply> BakeClient::post(const std::string& path, const std::string& body,
                                     const std::string& type) {
  return impl_->reply(impl_->http.Post(path.c_str(), impl_->auth, body, type.c_str()),
                      "POST " + path);
}

Expected<HttpReply> BakeClient::patch(const std::string& path, const std::string& body) {
  return impl_->reply(impl_->http.Patch(path.c_str(), impl_->auth, body, "application/json"),
                      "PATCH " + path);
}

Expected<HttpReply> BakeClient::del(const std::string& path) {
  return impl_->reply(impl_->http.Delete(path.c_str(), impl_->auth), "DELETE " + path);
}

namespace {

Expected<json> jsonReply(const Expected<HttpReply>& r) {
  if (!r) return r.status();
  if (!r->ok()) return httpErrorStatus(*r);
  json j = json::parse(r->body, nullptr, false);
  if (j.is_discarded()) return Status::error("the server sent malformed JSON");
  return j;
}

}  // namespace

Expected<json> BakeClient::uploadScene(const std::string& scene_json) {
  return jsonReply(post("/v1/scenes", scene_json));
}

Expected<json> BakeClient::submitBake(const std::string& scene_id, const json& request) {
  return jsonReply(post("/v1/scenes/" + scene_id + "/bakes", request.dump()));
}

Expected<json> BakeClient::job(const std::string& job_id) {
  return jsonReply(get("/v1/jobs/" + job_id));
}

Expected<json> BakeClient::waitForJob(const std::string& job_id, double timeout_s,
                                      const std::function<void(const json&)>& on_progress) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (true) {
    Expected<json> j = job(job_id);
    if (!j) return j;
    if (on_progress) on_progress(*j);
    const std::string state = (*j).value("state", "");
    if (state != "queued" && state != "running") return j;
    if (std::chrono::steady_clock::now() > deadline)
      return Status::error("timed out waiting for job " + job_id);
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
}

Expected<std::string> BakeClient::download(const std::string& job_id, const std::string& name) {
  Expected<HttpReply> r = get("/v1/jobs/" + job_id + "/" + name);
  if (!r) return r.status();
  if (!r->ok()) return httpErrorStatus(*r);
  return std::move(r->body);
}

Expected<JobProgress> BakeClient::jobProgress(const std::string& job_id, double wait_s,
                                              int passes) {
  std::string path = "/v1/jobs/" + job_id;
  if (wait_s > 0.0) {
    path += "?wait=" + std::to_string(std::max(1, std::min(30, int(wait_s + 0.5))));
    if (passes > 0) path += "&passes=" + std::to_string(passes);
  }
  Expected<json> j = jsonReply(get(path));
  if (!j) return j.status();
  return parseJobProgress(*j);
}

Expected<AtlasDelta> BakeClient::fetchDelta(const std::string& job_id, const std::string& from,
                                            int pass) {
  auto body =
      download(job_id, "delta.bin?from=" + from + "&pass=" + std::to_string(std::max(0, pass)));
  if (!body) return body.status();
  return decodeAtlasDelta(*body);
}

Expected<json> BakeClient::patchScene(const std::string& scene_id, const json& body) {
  return jsonReply(patch("/v1/scenes/" + scene_id, body.dump()));
}

Expected<json> BakeClient::cancelJob(const std::string& job_id) {
  return jsonReply(del("/v1/jobs/" + job_id));
}

const std::string& BakeClient::url() const {
  return impl_->url;
}

}  // namespace rdm
