// The dispatch budget's policy (rdm/vulkan/dispatch_budget.h), deterministic: what it does
// after dispatches over, within and well under the budget. The bake's use of it on a real
// device is VulkanBake.DispatchBudgetSplitsHeavyUnitsWithTheSameBits.
#include <gtest/gtest.h>

#include "rdm/vulkan/dispatch_budget.h"

namespace rdm {
namespace {

TEST(DispatchBudget, StartsSmallAndGrowsWhileDispatchesAreShort) {
  DispatchBudget b(0.5, 60000, 1000);
  EXPECT_EQ(b.loopBudget(), DispatchBudget::kStartLoopBudget);
  EXPECT_EQ(b.maxJobs(), 1000u);
  b.observe(0.2);  // within the budget, over a quarter of it: no change
  EXPECT_EQ(b.loopBudget(), DispatchBudget::kStartLoopBudget);
  for (int i = 0; i < 10; ++i) b.observe(0.01);
  EXPECT_EQ(b.loopBudget(), 60000u);  // doubled up to the ceiling, never past it
  EXPECT_EQ(b.maxJobs(), 1000u);
}

TEST(DispatchBudget, LongDispatchesHalveTheLoopBudgetThenTheBatch) {
  DispatchBudget b(0.5, 60000, 1000);
  for (int i = 0; i < 4; ++i) b.observe(2.0);
  EXPECT_EQ(b.loopBudget(), DispatchBudget::kMinLoopBudget);  // 4096 -> 256
  EXPECT_EQ(b.maxJobs(), 1000u);
  b.observe(2.0);
  EXPECT_EQ(b.maxJobs(), 500u);
  for (int i = 0; i < 20; ++i) b.observe(2.0);
  EXPECT_EQ(b.maxJobs(), 1u);  // never zero
  EXPECT_EQ(b.loopBudget(), DispatchBudget::kMinLoopBudget);
  // Short dispatches give the batch back first, then the loop budget.
  for (int i = 0; i < 10; ++i) b.observe(0.01);
  EXPECT_EQ(b.maxJobs(), 1000u);
  EXPECT_EQ(b.loopBudget(), DispatchBudget::kMinLoopBudget);
  b.observe(0.01);
  EXPECT_EQ(b.loopBudget(), 2 * DispatchBudget::kMinLoopBudget);
}

TEST(DispatchBudget, NoBudgetRunsAtTheCeiling) {
  DispatchBudget b(0.0, 60000, 1000);
  EXPECT_EQ(b.loopBudget(), 60000u);
  b.observe(100.0);
  EXPECT_EQ(b.loopBudget(), 60000u);
  EXPECT_EQ(b.maxJobs(), 1000u);
}

}  // namespace
}  // namespace rdm
