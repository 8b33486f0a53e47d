#include "rdm/bake/preview_pass.h"

#include <gtest/gtest.h>

#include "rdm/transport/rdm_shared_cpp.h"

namespace rdm {
namespace {

TEST(PreviewPass, PreviewIsNaiveOneBounceAtHalfTheCapAndOnlyWhenFourTimesCheaper) {
  BakeSettings s;
  s.spp = 16, s.max_bounces = 3, s.max_hemisphere = 64, s.estimator = Estimator::kPrefiltered;
  const std::vector<BakeSettings> passes = progressivePasses(s);
  ASSERT_EQ(passes.size(), 2u);
  EXPECT_EQ(passes[0].spp, 1);
  EXPECT_EQ(passes[0].max_bounces, 1);
  EXPECT_EQ(passes[0].estimator, Estimator::kNaive);
  EXPECT_EQ(passes[0].max_hemisphere, 32);
  EXPECT_EQ(passes[0].seed, s.seed);
  EXPECT_EQ(passes[1], s);
  s.spp = 3;  // 1 spp is not 4x fewer samples
  EXPECT_EQ(progressivePasses(s), std::vector<BakeSettings>{s});
  s.spp = 4, s.max_hemisphere = 2;  // the cap never falls below the smallest size
  EXPECT_EQ(progressivePasses(s).front().max_hemisphere, 2);
}

TEST(PreviewPass, PassSizesFollowTheCapPerLevel) {
  BakeSettings preview;
  preview.max_hemisphere = 32;
  const std::vector<RdmId> plan = {{{1, 0, 2}, 0, 64}, {{1, 0, 2}, 3, 32}, {{0, 0, 0}, 7, 2}};
  const std::vector<RdmId> out = atPassSizes(plan, preview);
  ASSERT_EQ(out.size(), 3u);
  EXPECT_EQ(out[0].size, 32);  // capped levels halve
  EXPECT_EQ(out[1].size, 32);  // 2^(8-3) = 32 is under the new cap: unchanged
  EXPECT_EQ(out[2].size, 2);
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(out[i].slot, plan[i].slot);
    EXPECT_EQ(out[i].level, plan[i].level);
    EXPECT_EQ(out[i].size, shared::hemisphereSize(plan[i].level, 32));
  }
}

TEST(PreviewPass, ExpandRepeatsEachTexelWithinItsFace) {
  Image small(2 * 2, 3 * 2, 4);  // s = 2
  for (int y = 0; y < 6; ++y)
    for (int x = 0; x < 4; ++x)
      for (int c = 0; c < 4; ++c) small.at(x, y, c) = float(100 * c + 10 * y + x);
  const Image big = expandRdmImage(small, 4);
  ASSERT_EQ(big.width, 8);
  ASSERT_EQ(big.height, 12);
  for (int f = 0; f < 6; ++f)
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i)
        for (int c = 0; c < 4; ++c) {
          const float want = small.at(2 * (f % 2) + i / 2, 2 * (f / 2) + j / 2, c);
          ASSERT_EQ(big.at(4 * (f % 2) + i, 4 * (f / 2) + j, c), want) << f << " " << i << j;
        }
  EXPECT_EQ(expandRdmImage(small, 2).pixels, small.pixels);  // same size: unchanged
}

}  // namespace
}  // namespace rdm
