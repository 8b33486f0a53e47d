// `rdm serve`: the bake daemon (docs/spec.md section 8, docs/api.md).
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <thread>

#include "cli_app.h"
#include "commands.h"
#include "http_server.h"
#include "listen_probe.h"
#include "number_checks.h"
#include "rdm/base/failpoint.h"
#include "rdm/base/log.h"
#include "rdm/image/exr_io.h"

namespace rdm::cli {
namespace {

struct IntOption {
  const char* name;
  long long lo, hi;
  int* target;
  const char* help;
};

// open()'s message, with the reason when it could not listen (it does not say why).
std::string openFailure(const Status& status, const server::ServerConfig& config) {
  if (status.message().rfind("cannot listen on ", 0) != 0) return status.message();
  const std::string reason = listenFailureReason(config.bind, config.port);
  return reason.empty() ? status.message() : status.message() + ": " + reason;
}

}  // namespace

int cmdServe(const Args& args) {
  server::ServerConfig config;
  VerbApp app("serve",
              "Run the bake daemon (HTTP API, job queue; docs/api.md). --port 0 picks "
              "a free port; the bound address is printed as 'listening on "
              "http://ADDR:PORT'.");
  app.add_option("--data-dir", config.data_dir, "scenes, jobs and results live here")->required();
  app.add_option("--bind", config.bind, "address to listen on");
  app.add_option("--token", config.token, "bearer token clients must send")
      ->default_str("$RDM_TOKEN, else none");
  std::string backend = "auto";
  app.add_option("--backend", backend,
                 "where RDMs bake: cpu, vulkan or auto (Vulkan on a GPU, else the CPU)")
      ->capture_default_str();
  app.add_option("--device", config.device, "Vulkan device by index or name")
      ->default_str("first GPU");
  app.add_option("--vulkan-call-paths", config.vulkan_call_paths,
                 "paths (texels x spp) per Vulkan call, whole RDMs: larger keeps a GPU busier, "
                 "smaller lets edits overtake a full bake and cancels land sooner")
      ->check(wholeNumberIn(1ll, 1ll << 40))
      ->capture_default_str();
  app.add_option("--result-passes", config.result_passes,
                 "where a Vulkan job encodes a bc6h atlas and denoises: auto (its device when "
                 "that is a GPU; on lavapipe the CPU is faster), vulkan or cpu; the same results")
      ->check(CLI::IsMember({"auto", "cpu", "vulkan"}))
      ->capture_default_str();
  app.add_option("--min-rate", config.min_rate,
                 "bytes per second a client must at least average sending a body or reading a "
                 "response, after --rate-grace; slower clients are disconnected")
      ->check(wholeNumberIn(1ll, 1ll << 40))
      ->capture_default_str();
  std::string log_level = "info";
  app.add_option("--log-level", log_level,
                 "debug, info, warn, error or off: JSON lines on stderr, one per request and "
                 "per job transition (docs/api.md, \"Logs\")")
      ->capture_default_str();
  long long max_body = (long long)config.max_body;
  app.add_option("--max-body", max_body, "largest request body in bytes")
      ->check(wholeNumberIn(1ll, 1ll << 32));
  app.add_option("--max-job-memory", config.max_job_memory,
                 "bytes of memory one job may need by its estimate; larger jobs are refused "
                 "with 422")
      ->check(wholeNumberIn(1ll << 20, 1ll << 50))
      ->default_str("half the physical memory");
  app.add_option("--max-placements", config.max_placements,
                 "placements per scene; larger uploads are refused with 413")
      ->check(wholeNumberIn(1ll, 1ll << 40))
      ->default_str("what --max-body and --max-job-memory allow");
  app.add_option("--max-data-bytes", config.max_data_bytes,
                 "bytes the data directory may hold: past it the oldest finished jobs no job "
                 "needs expire (0: no limit)")
      ->check(wholeNumberIn(0ll, 1ll << 60))
      ->capture_default_str();
  const IntOption options[] = {
      {"--port", 0, 65535, &config.port, "TCP port"},
      {"--threads", 0, 1024, &config.threads, "bake threads (0: all cores)"},
      {"--max-grid", 1, 256, &config.max_grid, "largest scene grid side in slots"},
      {"--max-spp", 1, 65536, &config.max_spp, "largest spp a job may ask for"},
      {"--max-hemisphere", 2, 256, &config.max_hemisphere, "largest hemisphere size S"},
      {"--max-jobs", 1, 100000, &config.max_jobs, "jobs kept"},
      {"--max-scenes", 1, 10000000, &config.max_scenes, "scenes kept"},
      {"--max-versions", 1, 1000000, &config.max_versions,
       "scene versions kept per scene, besides those jobs need"},
      {"--http-threads", 1, 1024, &config.http_threads, "HTTP worker threads"},
      {"--http-queue", 1, 100000, &config.http_queue, "queued HTTP connections"},
      {"--read-timeout", 1, 3600, &config.read_timeout_s, "request read timeout, seconds"},
      {"--write-timeout", 1, 3600, &config.write_timeout_s, "reply write timeout, seconds"},
      {"--head-timeout", 1, 3600, &config.head_timeout_s, "whole request head deadline, seconds"},
      {"--body-timeout", 1, 86400, &config.body_timeout_s, "whole request body deadline, seconds"},
      {"--listen-backlog", 1, 65535, &config.listen_backlog, "listen() backlog"},
      {"--rate-grace", 0, 3600, &config.rate_grace_s,
       "seconds a body or response may take before --min-rate applies"},
      {"--max-parked-polls", 0, 1000000, &config.max_parked_polls,
       "long polls parked without a thread; more wait on an HTTP worker"},
      {"--keep-jobs", 0, 100000000, &config.keep_jobs,
       "finished jobs kept; older ones expire (0: no limit)"},
      {"--fetch-grace", 0, 100000000, &config.fetch_grace_s,
       "seconds after a fetch of its results that a job does not expire"},
  };
  for (const IntOption& o : options)
    app.add_option(o.name, *o.target, o.help)->check(wholeNumberIn(o.lo, o.hi));
  if (auto code = parseArgs(app, args)) return *code;
  config.max_body = size_t(max_body);
  LogLevel level{};
  if (!parseLogLevel(log_level, level))
    return fail("serve", "--log-level: '" + log_level + "' is not debug, info, warn, error or off",
                2);
  setLogLevel(level);
  auto requested = parseBakeBackend(backend);
  if (!requested) return fail("serve", "--backend: " + requested.error(), 2);
  if (*requested == BakeBackend::kCpu && !config.device.empty())
    return fail("serve", "--device selects a Vulkan device; it does not apply to --backend cpu", 2);
  config.backend = *requested;
  if (const char* env = std::getenv("RDM_TOKEN"); env && !app.count("--token")) config.token = env;
  server::resolveAdmissionLimits(config);
  if (Status s = armFailpointFromEnvironment(); !s) return fail("serve", s.message(), 2);

  // SIGINT / SIGTERM stop the server from a dedicated thread; every other thread blocks them.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  std::signal(SIGPIPE, SIG_IGN);
  // Atlas pages compress on as many workers as jobs bake on; after the mask, which the pool's
  // threads inherit, so SIGTERM reaches the stopping thread and not a worker's default action.
  setExrThreads(config.threads);

  server::BakeServer server(config);
  if (Status s = server.open(); !s) return fail("serve", openFailure(s, config));
  logEvent(LogLevel::kInfo, "start",
           {{"version", versionText()},
            {"backend", server.backendLine()},
            {"listen", config.bind + ":" + std::to_string(server.port())},
            {"data_dir", config.data_dir}});
  std::printf("listening on http://%s:%d\n", config.bind.c_str(), server.port());
  std::fflush(stdout);
  std::thread waiter([&] {
    int sig = 0;
    sigwait(&signals, &sig);
    logEvent(LogLevel::kInfo, "stop", {{"signal", sig == SIGINT ? "SIGINT" : "SIGTERM"}});
    server.stop();
  });
  Status status = server.run();
  pthread_kill(waiter.native_handle(), SIGTERM);  // releases the waiter when run() ended on its own
  waiter.join();
  if (!status) return fail("serve", status.message());
  return 0;
}

}  // namespace rdm::cli
