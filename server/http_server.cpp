#include "http_server.h"

#include <cstdio>

#include <httplib.h>

#include "api.h"
#include "bounded_queue.h"
#include "http_util.h"

namespace rdm::server {
namespace {

using HR = httplib::Server::HandlerResponse;

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

// Runs before the body is read: auth, then refuses bodies we will not read.
HR preRoute(const ServerConfig& config, const httplib::Request& req, httplib::Response& res) {
  if (!config.token.empty() && req.path != "/healthz") {
    const std::string auth = req.get_header_value("Authorization");
    if (!constantTimeEquals(auth, "Bearer " + config.token)) {
      res.set_header("WWW-Authenticate", "Bearer");
      return reject(req, res,
                    {401,
                     "unauthorized",
                     "Missing or wrong bearer token",
                     "send 'Authorization: Bearer <token>'",
                     {}});
    }
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
  if (req.has_header("Content-Encoding") &&
      req.get_header_value("Content-Encoding") != "identity") {
    return reject(req, res,
                  {415,
                   "unsupported-encoding",
                   "Compressed bodies are not accepted",
                   "Content-Encoding '" + req.get_header_value("Content-Encoding") + "' refused",
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
                   "send 'Content-Type: application/json' (got '" + type + "')",
                   {}});
  }
  if (req.has_header("Content-Length")) {
    const std::string v = req.get_header_value("Content-Length");
    char* end = nullptr;
    unsigned long long n = std::strtoull(v.c_str(), &end, 10);
    if (v.empty() || *end) return reject(req, res, badRequest("malformed Content-Length"));
    if (n > config.max_body) {
      return reject(
          req, res,
          {413,
           "body-too-large",
           "Request body too large",
           "body of " + v + " bytes exceeds the limit of " + std::to_string(config.max_body),
           {}});
    }
  }
  if (req.has_header("Range") && req.get_header_value("Range").find(',') != std::string::npos) {
    return reject(
        req, res,
        {416, "multi-range", "Multiple ranges are not supported", "ask for one range", {}});
  }
  return HR::Unhandled;
}

}  // namespace

struct BakeServer::Impl {
  ServerConfig config;
  SceneStore scenes;
  JobStore store;
  Metrics metrics;
  JobManager jobs;
  ApiContext ctx;
  httplib::Server http;
  int port = 0;

  explicit Impl(ServerConfig c)
      : config(std::move(c)),
        scenes(config.data_dir),
        store(config.data_dir),
        jobs(config, scenes, store, metrics),
        ctx{config, scenes, jobs, metrics} {}
  void configureHttp();
};

void BakeServer::Impl::configureHttp() {
  const size_t threads = size_t(std::max(1, config.http_threads)),
               queue = size_t(std::max(1, config.http_queue));
  http.new_task_queue = [threads, queue] { return new BoundedTaskQueue(threads, queue); };
  http.set_keep_alive_max_count(1);  // no worker pinned by an idle keep-alive connection
  http.set_read_timeout(config.read_timeout_s, 0);
  http.set_write_timeout(config.write_timeout_s, 0);
  http.set_payload_max_length(config.max_body);
  http.set_pre_routing_handler(
      [this](const auto& req, auto& res) { return preRoute(config, req, res); });
  http.set_exception_handler(
      [](const httplib::Request& req, httplib::Response& res, std::exception_ptr) {
        writeProblem(res, internalError(), req.path);  // never echoes what()
      });
  http.set_error_handler(
      httplib::Server::HandlerWithResponse([](const httplib::Request& req, httplib::Response& res) {
        if (!res.body.empty()) return HR::Unhandled;
        Problem p{res.status,
                  "http-" + std::to_string(res.status),
                  statusTitle(res.status),
                  res.status == 404 ? "no route for " + req.method + " " + req.path
                                    : "the request was refused",
                  {}};
        if (res.status == 413) p.detail = "request body exceeds the server's limit";
        writeProblem(res, p, req.path);
        return HR::Handled;
      }));
  http.set_logger([this](const httplib::Request&, const httplib::Response& res) {
    metrics.countRequest(res.status);
  });
  http.Get("/healthz", [](const httplib::Request&, httplib::Response& res) {
    res.set_content("{\"status\": \"ok\"}\n", "application/json");
  });
  http.Get("/metrics", [this](const httplib::Request&, httplib::Response& res) {
    res.set_content(metrics.render(jobs.gauges()), "text/plain; version=0.0.4; charset=utf-8");
  });
  registerSceneRoutes(http, ctx);
  registerJobRoutes(http, ctx);
  registerResultRoutes(http, ctx);
}

BakeServer::BakeServer(ServerConfig config) : impl_(std::make_unique<Impl>(std::move(config))) {}
BakeServer::~BakeServer() {
  stop();
  impl_->jobs.stop();
}

Status BakeServer::open() {
  if (Status s = impl_->scenes.load(); !s) return s;
  impl_->configureHttp();
  if (impl_->config.port == 0) {
    impl_->port = impl_->http.bind_to_any_port(impl_->config.bind);
  } else if (impl_->http.bind_to_port(impl_->config.bind, impl_->config.port)) {
    impl_->port = impl_->config.port;
  } else {
    impl_->port = -1;
  }
  if (impl_->port <= 0) {
    return Status::error("cannot listen on " + impl_->config.bind + ":" +
                         std::to_string(impl_->config.port));
  }
  return impl_->jobs.start();
}

int BakeServer::port() const {
  return impl_->port;
}

Status BakeServer::run() {
  if (!impl_->http.listen_after_bind())
    return Status::error("the HTTP server stopped with an error");
  return {};
}

void BakeServer::stop() {
  if (impl_->http.is_running()) impl_->http.stop();
}

}  // namespace rdm::server
