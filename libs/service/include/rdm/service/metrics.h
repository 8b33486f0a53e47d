// Counters for GET /metrics (Prometheus text format 0.0.4). Gauges that describe jobs
// (queue depth, jobs by state) are passed in at scrape time.
#pragma once

#include <atomic>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>

namespace rdm {

struct JobGauges {
  std::map<std::string, int> jobs_by_state;  // every state name present, 0 included
  int queue_depth = 0;                       // jobs queued or running
  uint64_t units_pending = 0;                // work units not yet run
};

class Metrics {
 public:
  void countRequest(int status);
  void addRays(uint64_t rays) { rays_ += rays; }
  void addBakeSeconds(double s);
  void jobFinished(const std::string& result);
  std::string render(const JobGauges& gauges) const;

 private:
  std::atomic<uint64_t> rays_{0};
  mutable std::mutex mutex_;
  double bake_seconds_ = 0.0;
  std::map<int, uint64_t> requests_;
  std::map<std::string, uint64_t> finished_;
};

}  // namespace rdm
