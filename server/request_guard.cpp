#include "request_guard.h"

#include <regex>

#include "http_util.h"

namespace rdm::server {
namespace {

using HR = httplib::Server::HandlerResponse;

struct RouteMethods {
  std::regex pattern;
  const char* allow;
};

// Every route of docs/api.md and the methods it takes; GET implies HEAD (httplib).
const std::vector<RouteMethods>& routeTable() {
  static const std::vector<RouteMethods> table = {
      {std::regex("/healthz"), "GET, HEAD, OPTIONS"},
      {std::regex("/metrics"), "GET, HEAD, OPTIONS"},
      {std::regex("/v1/scenes"), "GET, HEAD, POST, OPTIONS"},
      {std::regex("/v1/scenes/[^/]+"), "GET, HEAD, PATCH, DELETE, OPTIONS"},
      {std::regex("/v1/scenes/[^/]+/bakes"), "POST, OPTIONS"},
      {std::regex("/v1/scenes/[^/]+/versions/[^/]+"), "DELETE, OPTIONS"},
      {std::regex("/v1/jobs"), "GET, HEAD, OPTIONS"},
      {std::regex("/v1/jobs/[^/]+"), "GET, HEAD, DELETE, OPTIONS"},
      {std::regex("/v1/jobs/[^/]+/(atlas\\.exr|index\\.json|index\\.txt|delta)"),
       "GET, HEAD, OPTIONS"},
      {std::regex("/v1/jobs/[^/]+/rdms/\\d+,\\d+,\\d+/\\d+\\.exr"), "GET, HEAD, OPTIONS"},
  };
  return table;
}

bool constantTimeEquals(const std::string& a, const std::string& b) {
  unsigned char diff = a.size() == b.size() ? 0 : 1;
  for (size_t i = 0; i < a.size(); ++i)
    diff |= uint8_t(a[i] ^ b[i % std::max<size_t>(1, b.size())]);
  return diff == 0;
}

const char* statusTitle(int status) {
  switch (status) {
    case 400:
      return "Bad Request";
    case 404:
      return "Not Found";
    case 405:
      return "Method Not Allowed";
    case 413:
      return "Payload Too Large";
    case 414:
      return "URI Too Long";
    case 416:
      return "Range Not Satisfiable";
    default:
      return status < 500 ? "Client Error" : "Server Error";
  }
}

HR reject(const httplib::Request& req, httplib::Response& res, Problem p) {
  writeProblem(res, p, req.path);
  return HR::Handled;
}

std::optional<Problem> checkAuth(const ServerConfig& config, const httplib::Request& req) {
  if (config.token.empty() || req.path == "/healthz") return std::nullopt;
  if (req.get_header_value_count("Authorization") > 1)
    return badRequest("more than one Authorization header");
  if (bearerMatches(req.get_header_value("Authorization"), config.token)) return std::nullopt;
  return Problem{401,
                 "unauthorized",
                 "Missing or wrong bearer token",
                 "send 'Authorization: Bearer <token>'",
                 {}};
}

std::string clip(const std::string& s) {  // header values quoted in details
  return s.size() <= 64 ? s : s.substr(0, 64) + "...";
}

}  // namespace

// RFC 9110 11.6.2 / RFC 6750 2.1: the scheme is case-insensitive, then one or more spaces.
bool bearerMatches(const std::string& header, const std::string& token) {
  const size_t sp = header.find_first_of(" \t");
  if (sp != 6) return false;
  std::string scheme = header.substr(0, 6);
  for (char& c : scheme) c = char(std::tolower(uint8_t(c)));
  const size_t start = header.find_first_not_of(" \t", sp);
  const std::string given = start == std::string::npos ? "" : header.substr(start);
  // Both tests run whatever the scheme, so the time does not tell which one failed.
  return (int(scheme == "bearer") & int(constantTimeEquals(given, token))) != 0;
}

HR preRoute(const ServerConfig& config, const httplib::Request& req, httplib::Response& res) {
  if (auto p = checkAuth(config, req)) {
    if (p->status == 401) res.set_header("WWW-Authenticate", "Bearer");
    return reject(req, res, *p);
  }
  if (req.has_header("Transfer-Encoding")) {
    return reject(req, res,
                  {411,
                   "length-required",
                   "Chunked bodies are not accepted",
                   "send the body with a Content-Length",
                   {}});
  }
  const bool body_method = req.method == "POST" || req.method == "PUT" || req.method == "PATCH";
  if (body_method && !req.has_header("Content-Length")) {
    return reject(req, res,
                  {411,
                   "length-required",
                   "Content-Length required",
                   "requests with a body need a Content-Length header",
                   {}});
  }
  if (req.get_header_value_count("Content-Length") > 1)
    return reject(req, res, badRequest("more than one Content-Length header"));
  if (req.has_header("Content-Encoding") &&
      req.get_header_value("Content-Encoding") != "identity") {
    return reject(
        req, res,
        {415,
         "unsupported-encoding",
         "Compressed bodies are not accepted",
         "Content-Encoding '" + clip(req.get_header_value("Content-Encoding")) + "' refused",
         {}});
  }
  // httplib parses url-encoded forms itself (and caps them at 8 KiB): JSON bodies only.
  const std::string type = req.get_header_value("Content-Type");
  if (body_method && req.get_header_value("Content-Length") != "0" &&
      type.rfind("application/json", 0) != 0) {
    return reject(req, res,
                  {415,
                   "unsupported-media-type",
                   "Bodies must be JSON",
                   "send 'Content-Type: application/json' (got '" + clip(type) + "')",
                   {}});
  }
  if (req.has_header("Content-Length")) {
    const std::string v = req.get_header_value("Content-Length");
    char* end = nullptr;
    unsigned long long n = std::strtoull(v.c_str(), &end, 10);
    if (v.empty() || *end || v[0] == '-')
      return reject(req, res, badRequest("malformed Content-Length"));
    if (n > config.max_body) {
      return reject(
          req, res,
          {413,
           "body-too-large",
           "Request body too large",
           "body of " + clip(v) + " bytes exceeds the limit of " + std::to_string(config.max_body),
           {}});
    }
  }
  return HR::Unhandled;
}

bool isResultFile(const std::string& path) {
  static const std::regex files(
      "/v1/jobs/[^/]+/(atlas\\.exr|index\\.json|index\\.txt|delta|rdms/\\d+,\\d+,\\d+/\\d+\\.exr)");
  return std::regex_match(path, files);
}

void applyRange(const httplib::Request& req, httplib::Response& res,
                const std::optional<std::string>& range) {
  if (!isResultFile(req.path) || res.status != 200) return;
  res.set_header("Accept-Ranges", "bytes");
  static const std::regex one("bytes=[ \t]*(\\d*)-(\\d*)[ \t]*");
  std::smatch m;
  if (!range || !std::regex_match(*range, m, one) || (m[1].length() == 0 && m[2].length() == 0))
    return;  // absent, several or malformed: the whole file (RFC 9110 14.2)
  if (m[1].length() > 18 || m[2].length() > 18) return;
  const unsigned long long size = res.body.size();
  unsigned long long first, last = size ? size - 1 : 0;
  if (m[1].length() == 0) {  // suffix: the last N bytes
    const unsigned long long n = std::stoull(m[2]);
    first = n == 0 ? size : (n >= size ? 0 : size - n);
  } else {
    first = std::stoull(m[1]);
    if (m[2].length()) {
      const unsigned long long given = std::stoull(m[2]);
      if (given < first) return;  // invalid, so ignored
      last = std::min(last, given);
    }
  }
  if (first >= size) {
    const std::string total = std::to_string(size);
    writeProblem(res,
                 {416,
                  "range-not-satisfiable",
                  "Range not satisfiable",
                  "the file has " + total + " bytes",
                  {}},
                 req.path);
    res.set_header("Content-Range", "bytes */" + total);
  } else {
    res.body = res.body.substr(first, last - first + 1);
    res.status = 206;
    res.set_header("Content-Range", "bytes " + std::to_string(first) + "-" + std::to_string(last) +
                                        "/" + std::to_string(size));
  }
  // httplib counted the whole body before this post-routing hook ran.
  res.headers.erase("Content-Length");
  res.set_header("Content-Length", std::to_string(res.body.size()));
}

HR routeError(const httplib::Request& req, httplib::Response& res) {
  if (!res.body.empty()) return HR::Unhandled;
  if (res.status == 404) {
    for (const RouteMethods& r : routeTable()) {
      if (!std::regex_match(req.path, r.pattern)) continue;
      res.set_header("Allow", r.allow);
      if (req.method == "OPTIONS") {
        res.status = 204;
        return HR::Handled;
      }
      writeProblem(res,
                   {405,
                    "method-not-allowed",
                    "Method not allowed",
                    req.method + " is not allowed on " + req.path + " (Allow: " + r.allow + ")",
                    {}},
                   req.path);
      return HR::Handled;
    }
  }
  Problem p{
      res.status,
      "http-" + std::to_string(res.status),
      statusTitle(res.status),
      res.status == 404 ? "no route for " + req.method + " " + req.path : "the request was refused",
      {}};
  if (res.status == 413) p.detail = "request body exceeds the server's limit";
  writeProblem(res, p, req.path);
  return HR::Handled;
}

}  // namespace rdm::server
