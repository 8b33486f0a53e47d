#include "http_server.h"

#include <malloc.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <regex>

#include <httplib.h>

#include "api.h"
#include "bounded_queue.h"
#include "head_reader.h"
#include "http_util.h"
#include "long_poll.h"
#include "rdm/base/log.h"
#include "rdm/service/data_dir.h"
#include "request_guard.h"
#include "socket_stream.h"

namespace rdm::server {
namespace {

using HR = httplib::Server::HandlerResponse;

constexpr size_t kTrimAfterBody = 1u << 20;  // bytes

// The request a worker thread is serving (its Range value lives here, not in httplib's
// Request, so httplib never builds multipart or unchecked range responses).
thread_local const PendingRequest* t_current = nullptr;

// cpp-httplib 0.11.4 with the accept loop handing sockets to a HeadReader instead of reading
// the head on a worker; workers serve complete heads through PrefixedSocketStream.
class HardenedHttp : public httplib::Server {
 public:
  std::function<void(int)> on_accept;
  void serve(PendingRequest& r, const ServerConfig& c, const std::atomic<bool>& aborted) {
    t_current = &r;
    const RateLimit rate{double(std::max(1ll, c.min_rate)), c.rate_grace_s * 1000};
    PrefixedSocketStream strm(r.sock, std::move(r.bytes), c.read_timeout_s * 1000,
                              c.write_timeout_s * 1000,
                              r.accepted + std::chrono::seconds(c.body_timeout_s), rate, aborted);
    bool closed = false;
    // The body is read into one allocation of its declared size (--max-body bounds it), not
    // a doubling string that peaks at three times the body.
    const size_t max_body = c.max_body;
    try {
      serveOne(strm, max_body, closed);
    } catch (const std::exception& e) {  // never escapes a worker thread
      logEvent(LogLevel::kError, "request_failed", {{"reason", e.what()}});
    }
    t_current = nullptr;
  }

 private:
  void serveOne(httplib::Stream& strm, size_t max_body, bool& closed) {
    process_request(strm, true, closed, [max_body](httplib::Request& req) {
      const unsigned long long n =
          std::strtoull(req.get_header_value("Content-Length").c_str(), nullptr, 10);
      if (n > 0 && n <= max_body) req.body.reserve(size_t(n));
    });
  }

  bool process_and_close_socket(socket_t sock) override {
    on_accept(sock);
    return true;
  }
};

}  // namespace

struct BakeServer::Impl {
  ServerConfig config;
  SceneStore scenes;
  JobStore store;
  Metrics metrics;
  JobManager jobs;
  ApiContext ctx;
  HardenedHttp http;
  // Requests with a body and those without get separate workers, so clients that send
  // their bodies slowly cannot hold every thread that job polls need; /healthz and /metrics
  // have their own, so they never queue behind either.
  BoundedTaskQueue workers, body_workers, control_workers;
  LongPollParker polls;
  HeadReader reader;
  std::atomic<bool> aborted{false};
  int data_lock = -1;  // lockDataDir's descriptor, closed last
  // The listening socket while httplib may accept on it; -1 once stop() or run() let it go.
  std::atomic<int> listen_fd{-1};
  int port = 0;

  explicit Impl(ServerConfig c)
      : config(std::move(c)),
        scenes(config.data_dir, config.max_versions),
        store(config.data_dir),
        jobs({config.threads, config.max_jobs, uint64_t(std::max(0ll, config.max_job_memory)),
              config.backend, config.device, uint64_t(config.vulkan_call_paths),
              RetentionPolicy{config.keep_jobs, uint64_t(std::max(0ll, config.max_data_bytes)),
                              double(config.fetch_grace_s)},
              config.result_passes},
             scenes, store, metrics),
        ctx{config, scenes, jobs, metrics},
        workers(size_t(std::max(1, config.http_threads)), size_t(std::max(1, config.http_queue))),
        body_workers(size_t(std::max(1, config.http_threads)),
                     size_t(std::max(1, config.http_queue))),
        control_workers(size_t(std::max(1, config.control_threads)), 64),
        polls(
            size_t(std::max(0, config.max_parked_polls)),
            [this](const auto& waits, double block_s) { return jobs.waitsOver(waits, block_s); },
            [this](PendingRequest& r) { serveOn(workers, r, true); }),
        reader(
            HeadLimits{size_t(config.max_header_bytes), config.max_header_fields,
                       config.head_timeout_s * 1000, size_t(std::max(1, config.max_pending_heads)),
                       2000},
            [this](PendingRequest& r) { return dispatch(r); },
            [this](int status) { refused(status); }) {}
  bool dispatch(PendingRequest& r) {
    if (!r.has_body && parkable(r)) return true;
    if (isControl(r.bytes)) return serveOn(control_workers, r, false);
    return serveOn(r.has_body ? body_workers : workers, r, false);
  }
  // `wait`: may block while the pool is full (the parker's release, never the reader).
  bool serveOn(BoundedTaskQueue& pool, PendingRequest& r, bool wait) {
    auto shared = std::make_shared<PendingRequest>(std::move(r));
    auto task = [this, shared] {
      http.serve(*shared, config, aborted);
      reader.linger(shared->sock);
      // glibc keeps a large body's pages in its arenas; give them back after one.
      if (shared->has_body && shared->body_bytes >= kTrimAfterBody) malloc_trim(0);
    };
    if (wait) {
      pool.enqueue(std::move(task));
      return true;
    }
    const bool taken = pool.tryEnqueue(std::move(task));
    if (!taken) r = std::move(*shared);  // the reader answers 503 on it
    return taken;
  }
  bool parkable(PendingRequest& r) {
    auto poll = parseLongPoll(r.bytes);
    if (!poll) return false;
    if (!config.token.empty()) {
      auto auth = headerValue(r.bytes, "authorization:");
      if (!auth || !bearerMatches(*auth, config.token)) return false;  // a worker answers 401
    }
    return polls.park(r, *poll);
  }
  static bool isControl(const std::string& head) {
    return head.rfind("GET /healthz ", 0) == 0 || head.rfind("GET /metrics ", 0) == 0;
  }
  void refused(int status) {
    metrics.countRequest(status);
    logEvent(LogLevel::kWarn, "request", {{"status", status}, {"refused_by", "head reader"}});
  }
  void configureHttp();
  void logRequest(const httplib::Request& req, const httplib::Response& res);
};

void BakeServer::Impl::configureHttp() {
  http.new_task_queue = [] { return new InlineTaskQueue(); };
  http.on_accept = [this](int sock) { reader.add(sock); };
  http.set_keep_alive_max_count(1);  // no worker pinned by an idle keep-alive connection
  http.set_read_timeout(config.read_timeout_s, 0);
  http.set_write_timeout(config.write_timeout_s, 0);
  http.set_payload_max_length(config.max_body);
  http.set_socket_options([this](socket_t sock) {
    int yes = 1;
    setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
    listen_fd = sock;  // the listening socket, for its backlog (open())
  });
  http.set_pre_routing_handler(
      [this](const auto& req, auto& res) { return preRoute(config, req, res); });
  // Refusals before the body is read answer instead of `100 Continue` (RFC 9110 10.1.1).
  http.set_expect_100_continue_handler([this](const auto& req, auto& res) {
    return preRoute(config, req, res) == HR::Handled ? res.status : 100;
  });
  http.set_post_routing_handler([](const auto& req, auto& res) {
    applyRange(req, res, t_current ? t_current->range : std::nullopt);
    if (res.status == 204) res.headers.erase("Content-Length");  // RFC 9110 8.6
  });
  http.set_exception_handler(
      [](const httplib::Request& req, httplib::Response& res, std::exception_ptr) {
        writeProblem(res, internalError(), req.path);  // never echoes what()
      });
  http.set_error_handler(httplib::Server::HandlerWithResponse(
      [](const httplib::Request& req, httplib::Response& res) { return routeError(req, res); }));
  http.set_logger([this](const httplib::Request& req, const httplib::Response& res) {
    metrics.countRequest(res.status);
    logRequest(req, res);
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

void BakeServer::Impl::logRequest(const httplib::Request& req, const httplib::Response& res) {
  const LogLevel level = res.status >= 500 ? LogLevel::kError : LogLevel::kInfo;
  if (!logEnabled(level)) return;
  double ms = 0.0;
  if (t_current)
    ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() -
                                                   t_current->accepted)
             .count();
  const size_t bytes = res.content_length_ > 0 ? res.content_length_ : res.body.size();
  logEvent(level, "request",
           {{"method", req.method},
            {"route", routeOf(req.path)},
            {"path", req.path},
            {"status", res.status},
            {"bytes", bytes},
            {"ms", std::round(ms * 10.0) / 10.0},
            {"client", req.remote_addr + ":" + std::to_string(req.remote_port)}});
}

BakeServer::BakeServer(ServerConfig config) : impl_(std::make_unique<Impl>(std::move(config))) {}
BakeServer::~BakeServer() {
  stop();
  impl_->polls.stop();
  impl_->reader.stop();
  impl_->workers.shutdown();
  impl_->control_workers.shutdown();
  impl_->body_workers.shutdown();
  impl_->jobs.stop();
  if (impl_->data_lock >= 0) ::close(impl_->data_lock);
}

Status BakeServer::open() {
  // Blocks of 4 MiB and more (request bodies, result files, a job's large buffers) are
  // mapped and unmapped on their own. glibc's default threshold rises after such a free up
  // to 32 MiB, and the freed top of a thread's arena above it stays resident: eight 30 MB
  // bodies on eight workers kept 250 MB (docs/deploy.md, "Memory after peaks").
  mallopt(M_MMAP_THRESHOLD, 4 << 20);
  auto lock = lockDataDir(impl_->config.data_dir);
  if (!lock) return lock.status();
  impl_->data_lock = *lock;
  sweepTempFiles(impl_->config.data_dir);
  if (Status s = impl_->scenes.load(); !s) return s;
  // Each connection whose head is arriving holds a descriptor: use the hard limit.
  rlimit files{};
  if (getrlimit(RLIMIT_NOFILE, &files) == 0 && files.rlim_cur < files.rlim_max) {
    files.rlim_cur = files.rlim_max;
    setrlimit(RLIMIT_NOFILE, &files);
  }
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
  // cpp-httplib 0.11.4 listens with a backlog of 5; listen() again on a listening socket
  // only resizes its queue (Linux).
  if (impl_->listen_fd < 0 || ::listen(impl_->listen_fd, impl_->config.listen_backlog) != 0)
    return Status::error("cannot set the listen backlog");
  if (Status s = impl_->reader.start(); !s) return s;
  impl_->polls.start();
  return impl_->jobs.start();
}

int BakeServer::port() const {
  return impl_->port;
}

std::string BakeServer::backendLine() const {
  return impl_->jobs.backendLine();
}

Status BakeServer::run() {
  const bool ok = impl_->http.listen_after_bind() || impl_->aborted;
  impl_->listen_fd = -1;      // httplib closed it
  impl_->polls.stop();        // every long poll answers now, with the job's state
  impl_->reader.stop();       // closes connections whose head is still arriving
  impl_->workers.shutdown();  // requests in flight finish; their reads abort (stop())
  impl_->control_workers.shutdown();
  impl_->body_workers.shutdown();
  if (!ok) return Status::error("the HTTP server stopped with an error");
  return {};
}

void BakeServer::stop() {
  impl_->aborted = true;
  // A stop that comes between open() and run()'s listen (a SIGTERM just after the daemon
  // printed its address) finds httplib not yet running: shutting the bound socket down makes
  // that listen return at once instead of serving for ever.
  if (const int fd = impl_->listen_fd.exchange(-1); fd >= 0) ::shutdown(fd, SHUT_RDWR);
  if (impl_->http.is_running()) impl_->http.stop();
}

}  // namespace rdm::server
