// Run-time configuration of `rdm serve`: where it stores data, where it listens, and the
// limits it enforces on requests and scenes (docs/api.md lists the flags).
#pragma once

#include <cstddef>
#include <string>

#include "rdm/vulkan/vulkan_bake.h"

namespace rdm::server {

struct ServerConfig {
  std::string data_dir;
  std::string bind = "127.0.0.1";            // loopback by default
  int port = 8080;                           // 0: ephemeral
  std::string token;                         // non-empty: bearer token required (not for /healthz)
  int threads = 0;                           // bake worker threads; 0: all cores
  BakeBackend backend = BakeBackend::kAuto;  // docs/spec.md section 8.4
  std::string device;  // Vulkan device by index or name; empty: the first choice
  long long vulkan_call_paths = 1ll << 22;  // JobManagerOptions::vulkan_call_paths
  std::string result_passes = "auto";       // JobManagerOptions::result_passes
  int http_threads = 8;                     // HTTP worker threads
  int http_queue = 64;                      // accepted connections waiting for a worker
  size_t max_body = 32u << 20;              // request body limit, bytes
  int max_grid = 256;                       // per axis
  int max_spp = 65536;
  int max_hemisphere = 256;
  int max_jobs = 64;  // queued + running jobs
  // Admission (docs/api.md, "Admission"), 0: derived by resolveAdmissionLimits at start.
  long long max_job_memory = 0;  // bytes one job may need (its estimate); 0: half the RAM
  long long max_placements = 0;  // per scene; 0: what max_body and max_job_memory allow
  int max_scenes = 10000;
  int max_versions = 8;       // scene versions kept per scene besides those jobs need (spec 8.3)
  int read_timeout_s = 5;     // per read of a request body
  int write_timeout_s = 30;   // per write of a response
  int head_timeout_s = 10;    // from accept until the request head is complete (408)
  int body_timeout_s = 60;    // from accept until the whole request is read
  int listen_backlog = 1024;  // kernel queue of connections not yet accepted
  int max_header_bytes = 64 << 10;  // request line + header fields (431)
  int max_header_fields = 100;      // (431)
  int max_pending_heads = 4096;     // connections whose head is still arriving (503)
  // Retention (docs/api.md, "Deleting and retention"; RetentionPolicy): finished jobs kept
  // (0: no count limit), bytes the data directory may hold (0: no limit), and how long
  // after a fetch of its results a job is spared, seconds.
  int keep_jobs = 1000;
  long long max_data_bytes = 0;
  int fetch_grace_s = 300;
  // The least average rate of a request body and of a response, after a grace: a client
  // slower than this loses its connection (docs/api.md, "Slow clients").
  long long min_rate = 256 << 10;  // bytes per second
  int rate_grace_s = 5;
  int max_parked_polls = 4096;  // long polls parked without a thread; more wait on a worker
  int control_threads = 2;      // workers for /healthz and /metrics only
};

// Derives the admission limits left 0 (limits.cpp): max_job_memory from the physical memory,
// max_placements from max_body and max_job_memory.
void resolveAdmissionLimits(ServerConfig& config);

}  // namespace rdm::server
