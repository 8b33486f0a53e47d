#include "http_util.h"

#include "rdm/base/hash.h"
#include "rdm/base/json_parse.h"
#include "rdm/base/log.h"

namespace rdm::server {
namespace {

using nlohmann::json;

}  // namespace

httplib::Server::Handler wrap(ApiHandler handler) {
  return [handler = std::move(handler)](const httplib::Request& req, httplib::Response& res) {
    std::optional<Problem> problem;
    try {
      problem = handler(req, res);
    } catch (const std::exception& e) {
      logEvent(LogLevel::kError, "exception",
               {{"method", req.method}, {"path", req.path}, {"reason", e.what()}});
      problem = internalError();
    }
    if (problem) {
      res.headers.erase("ETag");
      res.headers.erase("Location");
      writeProblem(res, *problem, req.path);
    }
  };
}

Expected<json> parseJsonBody(const std::string& body) {
  if (body.empty()) return json::object();
  json j;
  if (Status parsed = parseJsonLimited(body, j); !parsed) return parsed;
  return j;
}

void sendJson(httplib::Response& res, const json& j, int status) {
  res.status = status;
  res.set_content(j.dump(1, ' ', false, json::error_handler_t::replace) + "\n", "application/json");
}

std::string bodyEtag(const std::string& body) {
  std::string etag = "\"";
  etag += contentHashHex(body);
  etag += '"';
  return etag;
}

bool handleEtag(const httplib::Request& req, httplib::Response& res, const std::string& etag) {
  res.set_header("ETag", etag);
  res.set_header("Cache-Control", "no-cache");
  if (!req.has_header("If-None-Match")) return false;
  const std::string list = req.get_header_value("If-None-Match");
  size_t pos = 0;
  while (pos <= list.size()) {
    size_t comma = list.find(',', pos);
    std::string tag =
        list.substr(pos, comma == std::string::npos ? std::string::npos : comma - pos);
    tag.erase(0, tag.find_first_not_of(" \t"));
    tag.erase(tag.find_last_not_of(" \t") + 1);
    if (tag.rfind("W/", 0) == 0) tag.erase(0, 2);
    if (tag == "*" || tag == etag) {
      res.status = 304;
      res.body.clear();
      return true;
    }
    if (comma == std::string::npos) break;
    pos = comma + 1;
  }
  return false;
}

std::variant<std::optional<long long>, Problem> queryInt(const httplib::Request& req,
                                                         const char* name, long long lo,
                                                         long long hi) {
  if (!req.has_param(name)) return std::optional<long long>();
  const std::string v = req.get_param_value(name);
  char* end = nullptr;
  long long x = std::strtoll(v.c_str(), &end, 10);
  if (v.empty() || *end || x < lo || x > hi) {
    return badRequest("query parameter '" + std::string(name) + "' must be an integer in " +
                          std::to_string(lo) + ".." + std::to_string(hi),
                      name);
  }
  return std::optional<long long>(x);
}

std::string routeOf(const std::string& path) {
  std::string out, prev, before_prev;
  size_t pos = 0;
  while (pos < path.size()) {
    const size_t slash = path.find('/', pos + 1);
    const size_t end = slash == std::string::npos ? path.size() : slash;
    std::string seg = path.substr(pos + 1, end - pos - 1);
    if (prev == "jobs" || prev == "scenes") {
      seg = "{id}";
    } else if (prev == "rdms") {
      seg = "{slot}";
    } else if (before_prev == "rdms") {
      seg = "{level}.exr";
    }
    out += "/" + seg;
    before_prev = prev, prev = path.substr(pos + 1, end - pos - 1);
    pos = end;
  }
  return out.size() > 200 ? out.substr(0, 200) : out;
}

}  // namespace rdm::server
