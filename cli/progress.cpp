#include "progress.h"

#include <unistd.h>

#include <cstdio>

namespace rdm::cli {

ProgressReporter::ProgressReporter(std::string unit)
    : unit_(std::move(unit)), tty_(isatty(STDERR_FILENO)) {}

std::string formatCount(double value) {
  char buf[32];
  if (value >= 1e9) {
    std::snprintf(buf, sizeof buf, "%.2f G", value / 1e9);
  } else if (value >= 1e6) {
    std::snprintf(buf, sizeof buf, "%.2f M", value / 1e6);
  } else if (value >= 1e3) {
    std::snprintf(buf, sizeof buf, "%.1f k", value / 1e3);
  } else {
    std::snprintf(buf, sizeof buf, "%.0f ", value);
  }
  return buf;
}

void ProgressReporter::update(int done, int total, uint64_t rays, double seconds) {
  if (seconds - last_print_ < (tty_ ? 0.1 : 2.0) && done < total) return;
  if (done == total && last_done_ == total) return;
  last_done_ = done;
  last_print_ = seconds;
  double fraction = total > 0 ? double(done) / total : 1.0;
  double rate = seconds > 0 ? double(rays) / seconds : 0.0;
  double eta = fraction > 0 ? seconds * (1.0 - fraction) / fraction : 0.0;
  if (tty_) {
    constexpr int kWidth = 30;
    int filled = int(fraction * kWidth);
    std::string bar(size_t(filled), '#');
    bar.append(size_t(kWidth - filled), '-');
    std::fprintf(stderr, "\r[%s] %d/%d %s  %srays/s  ETA %.0f s   ", bar.c_str(), done, total,
                 unit_.c_str(), formatCount(rate).c_str(), eta);
  } else {
    std::fprintf(stderr, "progress: %d/%d %s (%.1f%%), %srays/s, ETA %.0f s\n", done, total,
                 unit_.c_str(), 100.0 * fraction, formatCount(rate).c_str(), eta);
  }
  printed_ = true;
}

void ProgressReporter::finish() {
  if (tty_ && printed_) std::fprintf(stderr, "\n");
}

}  // namespace rdm::cli
