// Progress reporting for long commands: a redrawn bar on a terminal, plain lines (at most
// one every two seconds) otherwise. Progress is measured in units of expected cost (texels),
// so a large RDM counts for what it costs; the count shown (RDMs, rows) is for the reader.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "rdm/base/eta.h"

namespace rdm::cli {

class ProgressReporter {
 public:
  // `phase` (may be empty) names the phase in every line: "progress: face light 12.5% ...".
  explicit ProgressReporter(std::string unit, std::string phase = {});
  // `done` / `total`: expected cost; `count` / `count_total`: what the line shows.
  void update(double done, double total, int count, int count_total, uint64_t rays, double seconds);
  void finish();

 private:
  std::string unit_, phase_;
  bool tty_;
  double last_print_ = -1e9;
  bool printed_ = false;
  bool finished_line_ = false;
  EtaEstimator eta_;
};

std::string formatCount(double value);       // 1234567 -> "1.23 M"
std::string formatDuration(double seconds);  // 75 -> "1 min 15 s"; 0.4 -> "< 1 s"

}  // namespace rdm::cli
