// Progress reporting for long commands: a redrawn bar on a terminal, plain lines (at most
// one every two seconds) otherwise.
#pragma once

#include <cstdint>
#include <string>

namespace rdm::cli {

class ProgressReporter {
 public:
  explicit ProgressReporter(std::string unit);
  void update(int done, int total, uint64_t rays, double seconds);
  void finish();

 private:
  std::string unit_;
  bool tty_;
  double last_print_ = -1e9;
  bool printed_ = false;
  int last_done_ = -1;
};

std::string formatCount(double value);  // 1234567 -> "1.23 M"

}  // namespace rdm::cli
