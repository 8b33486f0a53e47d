// Remaining-time estimate for progress displays (the rdm CLI; usable by any front end).
// Progress is a fraction of expected cost (texels, not RDMs), so one large item does not
// stall the estimate.
#pragma once

#include <optional>

namespace rdm {

// No estimate until it means something (at least kMinFraction done and kMinSeconds
// elapsed); then the raw estimate elapsed * (1 - f) / f is smoothed exponentially (time
// constant kSmoothingSeconds) against the previous estimate counted down by the time passed.
// 0 once the fraction reaches 1.
class EtaEstimator {
 public:
  static constexpr double kMinFraction = 0.05, kMinSeconds = 1.0, kSmoothingSeconds = 5.0;
  std::optional<double> update(double fraction, double seconds);

 private:
  std::optional<double> eta_;
  double last_seconds_ = 0.0;
};

}  // namespace rdm
