// Progress reporting for long commands: a redrawn bar on a terminal, plain lines (at most
// one every two seconds) otherwise. Progress is measured in units of expected cost (texels),
// so a large RDM counts for what it costs; the count shown (RDMs, rows) is for the reader.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace rdm::cli {

// Remaining time from the fraction done. No estimate until it means something (at least
// kMinFraction done and kMinSeconds elapsed); then the raw estimate elapsed * (1 - f) / f
// is smoothed exponentially (time constant kSmoothingSeconds) against the previous estimate
// counted down by the time passed.
class EtaEstimator {
 public:
  static constexpr double kMinFraction = 0.05, kMinSeconds = 1.0, kSmoothingSeconds = 5.0;
  std::optional<double> update(double fraction, double seconds);

 private:
  std::optional<double> eta_;
  double last_seconds_ = 0.0;
};

class ProgressReporter {
 public:
  explicit ProgressReporter(std::string unit);
  // `done` / `total`: expected cost; `count` / `count_total`: what the line shows.
  void update(double done, double total, int count, int count_total, uint64_t rays, double seconds);
  void finish();

 private:
  std::string unit_;
  bool tty_;
  double last_print_ = -1e9;
  bool printed_ = false;
  bool finished_line_ = false;
  EtaEstimator eta_;
};

std::string formatCount(double value);       // 1234567 -> "1.23 M"
std::string formatDuration(double seconds);  // 75 -> "1 min 15 s"

}  // namespace rdm::cli
