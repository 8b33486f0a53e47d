// The progress ETA: silent until meaningful, steady through a stall, close at the end.
#include <gtest/gtest.h>

#include <cmath>

#include "rdm/base/eta.h"

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

// Progress that stalls for 1.8 s on one large unit: the raw estimate elapsed * (1 - f) / f
// climbs by more than 5 s, the shown one keeps counting down (it may rise, but slowly).
TEST(Eta, DoesNotJumpUpDuringAStall) {
  EtaEstimator eta;
  ASSERT_TRUE(eta.update(0.2, 2.0));  // 8 s left
  double raw_rise = 0.0, shown_highest = 0.0;
  for (int step = 1; step < 90; ++step) {  // updates every 20 ms, as the CLI's
    const double t = 2.0 + 0.02 * step;
    auto shown = eta.update(0.2, t);
    ASSERT_TRUE(shown);
    raw_rise = std::max(raw_rise, t * 0.8 / 0.2 - 8.0);
    shown_highest = std::max(shown_highest, *shown);
  }
  EXPECT_GT(raw_rise, 5.0);
  EXPECT_LE(shown_highest, 8.0);
  auto after_jump = eta.update(0.5, 3.8);  // the unit finished: 0.3 done in one step
  ASSERT_TRUE(after_jump);
  EXPECT_LT(*after_jump, 8.0);
}

// A bake whose cost per texel drops by 3x part way (as measured on island: slow large RDMs
// first, then fast small ones). Over the last fifth of the time the estimate, which
// follows the recent rate, is off by less than half as much as the average-rate one.
TEST(Eta, FollowsTheRecentRateNearTheEnd) {
  EtaEstimator eta;
  const double slow = 0.05, fast = 0.15;  // fraction per second
  const double switch_time = 0.4 / slow, end = switch_time + 0.6 / fast;
  double shown_error = 0.0, average_error = 0.0;
  for (double t = 1.0; t < end; t += 0.02) {
    const double f = t < switch_time ? slow * t : 0.4 + fast * (t - switch_time);
    auto shown = eta.update(f, t);
    if (t < 0.8 * end) continue;
    ASSERT_TRUE(shown);
    shown_error = std::max(shown_error, std::abs(*shown - (end - t)));
    average_error = std::max(average_error, std::abs(t * (1.0 - f) / f - (end - t)));
  }
  EXPECT_GT(average_error, 1.0);
  EXPECT_LT(shown_error, 0.5 * average_error) << shown_error << " vs " << average_error;
}

}  // namespace
}  // namespace rdm
