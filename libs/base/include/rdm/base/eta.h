// Remaining-time estimate for progress displays (the rdm CLI; usable by any front end).
// Progress is a fraction of expected cost (texels, not RDMs), so one large item does not
// stall the estimate.
#pragma once

#include <optional>

namespace rdm {

// No estimate until it means something: at least kMinFraction done and kMinSeconds
// elapsed. Then the rate (fraction per second) starts as the average so far and follows the
// recent rate exponentially (time constant kRateSeconds), because the cost per texel varies
// across a bake; the raw estimate is (1 - f) / max(recent rate, average rate), so a stall
// does not read as a collapse of the rate. The shown estimate counts down with
// the clock and moves towards the raw one quickly when that is lower (kFallSeconds) and
// slowly when it is higher (kRiseSeconds), so a short stall does not make it jump up.
// 0 once the fraction reaches 1.
class EtaEstimator {
 public:
  static constexpr double kMinFraction = 0.05, kMinSeconds = 1.0;
  static constexpr double kRateSeconds = 1.0, kFallSeconds = 0.25, kRiseSeconds = 10.0;
  std::optional<double> update(double fraction, double seconds);

 private:
  std::optional<double> eta_;
  double rate_ = 0.0, last_fraction_ = 0.0, last_seconds_ = 0.0;
};

}  // namespace rdm
