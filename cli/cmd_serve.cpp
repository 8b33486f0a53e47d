// `rdm serve`: the bake daemon (SPEC section 8, docs/api.md).
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <thread>

#include "args.h"
#include "commands.h"
#include "http_server.h"

namespace rdm::cli {
namespace {

constexpr const char* kUsage =
    "usage: rdm serve --data-dir DIR [--port P] [--bind ADDR] [--token T] [--threads N]\n"
    "                 [--max-body BYTES] [--max-grid N] [--max-spp N] [--max-hemisphere S]\n"
    "                 [--max-jobs N] [--max-scenes N] [--http-threads N] [--http-queue N]\n"
    "                 [--read-timeout S] [--write-timeout S] [--head-timeout S]\n"
    "                 [--body-timeout S] [--listen-backlog N]\n"
    "  --port 0 picks a free port; the bound address is printed as 'listening on "
    "http://ADDR:PORT'.\n"
    "  The token may also come from the environment variable RDM_TOKEN.\n";

struct IntOption {
  const char* name;
  long long lo, hi;
  std::function<void(long long)> set;
};

std::string readOptions(const ArgParser& p, server::ServerConfig& c) {
  const IntOption options[] = {
      {"--port", 0, 65535, [&](long long v) { c.port = int(v); }},
      {"--threads", 0, 1024, [&](long long v) { c.threads = int(v); }},
      {"--max-body", 1, 1ll << 32, [&](long long v) { c.max_body = size_t(v); }},
      {"--max-grid", 1, 256, [&](long long v) { c.max_grid = int(v); }},
      {"--max-spp", 1, 65536, [&](long long v) { c.max_spp = int(v); }},
      {"--max-hemisphere", 2, 256, [&](long long v) { c.max_hemisphere = int(v); }},
      {"--max-jobs", 1, 100000, [&](long long v) { c.max_jobs = int(v); }},
      {"--max-scenes", 1, 10000000, [&](long long v) { c.max_scenes = int(v); }},
      {"--http-threads", 1, 1024, [&](long long v) { c.http_threads = int(v); }},
      {"--http-queue", 1, 100000, [&](long long v) { c.http_queue = int(v); }},
      {"--read-timeout", 1, 3600, [&](long long v) { c.read_timeout_s = int(v); }},
      {"--write-timeout", 1, 3600, [&](long long v) { c.write_timeout_s = int(v); }},
      {"--head-timeout", 1, 3600, [&](long long v) { c.head_timeout_s = int(v); }},
      {"--body-timeout", 1, 86400, [&](long long v) { c.body_timeout_s = int(v); }},
      {"--listen-backlog", 1, 65535, [&](long long v) { c.listen_backlog = int(v); }},
  };
  std::string error;
  for (const IntOption& o : options) {
    auto v = p.integer(o.name, error);
    if (!error.empty()) return error;
    if (!v) continue;
    if (*v < o.lo || *v > o.hi) {
      return std::string("option ") + o.name + " must be in " + std::to_string(o.lo) + ".." +
             std::to_string(o.hi);
    }
    o.set(*v);
  }
  return {};
}

}  // namespace

int cmdServe(const Args& args) {
  ArgParser parser({"--data-dir", "--port", "--bind", "--token", "--threads", "--max-body",
                    "--max-grid", "--max-spp", "--max-hemisphere", "--max-jobs", "--max-scenes",
                    "--http-threads", "--http-queue", "--read-timeout", "--write-timeout",
                    "--head-timeout", "--body-timeout", "--listen-backlog"},
                   {"--help"});
  if (std::string e = parser.parse(args); !e.empty() || parser.flag("--help")) {
    std::fprintf(stderr, "%s%s", e.empty() ? "" : ("rdm serve: " + e + "\n").c_str(), kUsage);
    return e.empty() ? 0 : 2;
  }
  server::ServerConfig config;
  if (auto dir = parser.value("--data-dir")) config.data_dir = *dir;
  if (config.data_dir.empty())
    return std::fprintf(stderr, "rdm serve: --data-dir DIR is required\n%s", kUsage), 2;
  if (auto bind = parser.value("--bind")) config.bind = *bind;
  if (const char* env = std::getenv("RDM_TOKEN")) config.token = env;
  if (auto token = parser.value("--token")) config.token = *token;
  if (std::string e = readOptions(parser, config); !e.empty())
    return std::fprintf(stderr, "rdm serve: %s\n", e.c_str()), 2;

  // SIGINT / SIGTERM stop the server from a dedicated thread; every other thread blocks them.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  std::signal(SIGPIPE, SIG_IGN);

  server::BakeServer server(config);
  if (Status s = server.open(); !s)
    return std::fprintf(stderr, "rdm serve: %s\n", s.message().c_str()), 1;
  std::printf("listening on http://%s:%d\n", config.bind.c_str(), server.port());
  std::fflush(stdout);
  std::thread waiter([&] {
    int sig = 0;
    sigwait(&signals, &sig);
    server.stop();
  });
  Status status = server.run();
  pthread_kill(waiter.native_handle(), SIGTERM);  // releases the waiter when run() ended on its own
  waiter.join();
  if (!status) return std::fprintf(stderr, "rdm serve: %s\n", status.message().c_str()), 1;
  return 0;
}

}  // namespace rdm::cli
