#include "rdm/base/eta.h"

#include <algorithm>
#include <cmath>

namespace rdm {

std::optional<double> EtaEstimator::update(double fraction, double seconds) {
  if (fraction >= 1.0) return eta_ = 0.0;
  if (!eta_) {
    if (fraction < kMinFraction || seconds < kMinSeconds) return std::nullopt;
    rate_ = fraction / seconds;
    eta_ = (1.0 - fraction) / rate_;
  } else {
    const double dt = seconds - last_seconds_;
    if (dt <= 0.0) return eta_;
    const double recent = std::max(0.0, fraction - last_fraction_) / dt;
    rate_ += (1.0 - std::exp(-dt / kRateSeconds)) * (recent - rate_);
    const double predicted = std::max(0.0, *eta_ - dt);
    const double rate = std::max(rate_, fraction / seconds);  // a stall is not a new rate
    const double raw = rate > 0.0 ? (1.0 - fraction) / rate : predicted;
    const double tau = raw < predicted ? kFallSeconds : kRiseSeconds;
    eta_ = predicted + (1.0 - std::exp(-dt / tau)) * (raw - predicted);
  }
  last_fraction_ = fraction;
  last_seconds_ = seconds;
  return eta_;
}

}  // namespace rdm
