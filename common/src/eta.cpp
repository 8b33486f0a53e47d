#include "rdm/eta.h"

#include <algorithm>
#include <cmath>

namespace rdm {

std::optional<double> EtaEstimator::update(double fraction, double seconds) {
  if (fraction >= 1.0) return eta_ = 0.0;
  if (fraction < kMinFraction || seconds < kMinSeconds) return std::nullopt;
  const double raw = seconds * (1.0 - fraction) / fraction;
  if (!eta_) {
    eta_ = raw;
  } else {
    const double dt = std::max(0.0, seconds - last_seconds_);
    const double predicted = std::max(0.0, *eta_ - dt);
    const double weight = 1.0 - std::exp(-dt / kSmoothingSeconds);
    eta_ = predicted + weight * (raw - predicted);
  }
  last_seconds_ = seconds;
  return eta_;
}

}  // namespace rdm
