// The progress ETA: silent until meaningful, smooth under uneven progress.
#include <gtest/gtest.h>

#include <cmath>

#include "rdm/eta.h"

namespace rdm {
namespace {

TEST(Eta, NoEstimateBeforeFivePercentAndOneSecond) {
  EtaEstimator eta;
  EXPECT_FALSE(eta.update(0.0, 0.0));
  EXPECT_FALSE(eta.update(0.027, 2.0));  // "ETA 93 s at 2.7 %" is not shown
  EXPECT_FALSE(eta.update(0.5, 0.5));    // too early to trust a rate
  auto first = eta.update(0.1, 2.0);
  ASSERT_TRUE(first);
  EXPECT_NEAR(*first, 18.0, 1e-9);  // 2 s * 0.9 / 0.1
  EXPECT_EQ(eta.update(1.0, 3.0).value_or(-1.0), 0.0);
}

// Progress that stalls on one large unit and then jumps: the raw estimate swings by a factor
// of 2 and more, the smoothed one moves less than half as far from its first value.
TEST(Eta, SmoothsAStallThenAJump) {
  EtaEstimator eta;
  ASSERT_TRUE(eta.update(0.2, 2.0));  // 8 s left
  double raw_swing = 0.0, smooth_swing = 0.0;
  for (int step = 1; step <= 10; ++step) {
    const double t = 2.0 + 0.2 * step;
    const double f = step < 10 ? 0.2 : 0.5;  // stalled, then a jump
    const double raw = t * (1.0 - f) / f;
    auto smoothed = eta.update(f, t);
    ASSERT_TRUE(smoothed);
    raw_swing = std::max(raw_swing, std::abs(raw - 8.0));
    smooth_swing = std::max(smooth_swing, std::abs(*smoothed - 8.0));
  }
  EXPECT_GT(raw_swing, 5.0);
  EXPECT_LT(smooth_swing, 0.5 * raw_swing);
}

}  // namespace
}  // namespace rdm
