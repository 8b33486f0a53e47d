// Wall-clock time as the service stores it (JobRecord and SceneInfo timestamps).
#pragma once

#include <chrono>

namespace rdm {

// Seconds since the Unix epoch (system clock, so it may step); for durations use
// std::chrono::steady_clock.
inline double nowSeconds() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

}  // namespace rdm
