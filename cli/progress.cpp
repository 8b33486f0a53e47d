#include "progress.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace rdm::cli {

ProgressReporter::ProgressReporter(std::string unit, std::string phase)
    : unit_(std::move(unit)),
      phase_(phase.empty() ? phase : phase + " "),
      tty_(isatty(STDERR_FILENO)) {}

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

std::string formatDuration(double seconds) {
  if (seconds < 1.0) return "< 1 s";
  char buf[48];
  const long long s = std::llround(seconds);
  if (s >= 3600) {
    std::snprintf(buf, sizeof buf, "%lld h %02lld min", s / 3600, s / 60 % 60);
  } else if (s >= 60) {
    std::snprintf(buf, sizeof buf, "%lld min %02lld s", s / 60, s % 60);
  } else {
    std::snprintf(buf, sizeof buf, "%lld s", s);
  }
  return buf;
}

void ProgressReporter::update(double done, double total, int count, int count_total, uint64_t rays,
                              double seconds) {
  const double fraction = total > 0 ? std::clamp(done / total, 0.0, 1.0) : 1.0;
  const std::optional<double> eta = eta_.update(fraction, seconds);
  const bool complete = fraction >= 1.0;
  if (complete && finished_line_) return;
  if (!complete && seconds - last_print_ < (tty_ ? 0.1 : 2.0)) return;
  last_print_ = seconds;
  finished_line_ = complete;
  const double rate = seconds > 0 ? double(rays) / seconds : 0.0;
  const std::string eta_text = complete ? "done" : eta ? "ETA " + formatDuration(*eta) : "ETA --";
  if (tty_) {
    constexpr int kWidth = 30;
    const int filled = int(fraction * kWidth);
    std::string bar(size_t(filled), '#');
    bar.append(size_t(kWidth - filled), '-');
    std::fprintf(stderr, "\r%s[%s] %5.1f%%  %d/%d %s  %srays/s  %s   ", phase_.c_str(), bar.c_str(),
                 100.0 * fraction, count, count_total, unit_.c_str(), formatCount(rate).c_str(),
                 eta_text.c_str());
  } else {
    std::fprintf(stderr, "progress: %s%.1f%% (%d/%d %s), %srays/s, %s\n", phase_.c_str(),
                 100.0 * fraction, count, count_total, unit_.c_str(), formatCount(rate).c_str(),
                 eta_text.c_str());
  }
  printed_ = true;
}

void ProgressReporter::finish() {
  if (tty_ && printed_) std::fprintf(stderr, "\n");
}

}  // namespace rdm::cli
