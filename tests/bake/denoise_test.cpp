// The cross-block denoiser (docs/denoise.md) on RDMs whose true radiance is known: a flat
// wall of blocks under the sky, with Gaussian noise of a stated standard error added. The
// wall's blocks all see the same radiance per direction, so any difference between two
// neighbouring blocks is noise or a seam the filter made.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <random>

#include "rdm/bake/denoise.h"

namespace rdm {
namespace {

constexpr int kSize = 8;
constexpr int kWall = 6;  // blocks along x and z
constexpr float kNoise = 0.2f;
constexpr float kSkyDepth = 1.0e4f;

// The truth of face +Y's texel (i, j): a smooth gradient of directions.
float truth(int i, int j) {
  return 1.0f + 0.5f * float(i) / kSize + 0.25f * float(j) / kSize;
}

// A wall block: only face +Y (2) stored, looking at the sky, each texel the truth plus noise.
RdmData wallBlock(int x, int z, std::mt19937& rng, float noise = kNoise) {
  RdmData rdm;
  rdm.id = RdmId{{x, 0, z}, 0, kSize};
  rdm.image = Image(2 * kSize, 3 * kSize, 4);
  rdm.stderr_rgb.assign(size_t(2 * kSize * 3 * kSize * 3), 0.0f);
  rdm.skipped.fill(true);
  rdm.skipped[2] = false;
  std::normal_distribution<float> gauss(0.0f, 1.0f);
  for (int j = 0; j < kSize; ++j) {
    for (int i = 0; i < kSize; ++i) {
      const size_t p = size_t(kSize + j) * size_t(2 * kSize) + size_t(i);
      const float value = truth(i, j) + noise * gauss(rng);
      for (int c = 0; c < 3; ++c) {
        rdm.image.pixels[p * 4 + size_t(c)] = value;
        rdm.stderr_rgb[p * 3 + size_t(c)] = noise;
      }
      rdm.image.pixels[p * 4 + 3] = kSkyDepth;
    }
  }
  return rdm;
}

std::vector<RdmData> wall(unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<RdmData> rdms;
  for (int x = 0; x < kWall; ++x)
    for (int z = 0; z < kWall; ++z) rdms.push_back(wallBlock(x, z, rng));
  return rdms;
}

float faceTexel(const RdmData& rdm, int i, int j) {
  return rdm.image.pixels[(size_t(kSize + j) * size_t(2 * kSize) + size_t(i)) * 4];
}

std::string spillDir() {
  const std::string dir = testing::TempDir() + "/denoise_" + std::to_string(getpid());
  std::filesystem::create_directories(dir);
  return dir;
}

std::vector<RdmData> denoised(const std::vector<RdmData>& rdms, const DenoiseSettings& settings,
                              DenoiseStats* stats_out = nullptr) {
  auto spill = RdmSpill::create(spillDir());
  EXPECT_TRUE(spill.ok());
  DenoiseStats stats;
  EXPECT_TRUE(denoiseRdms(MemoryRdmSource(rdms), nullptr, **spill, settings, 2, stats));
  std::vector<RdmData> out;
  for (size_t i = 0; i < rdms.size(); ++i)
    EXPECT_TRUE((*spill)->visit(i, [&](const RdmData& d) { out.push_back(d); }));
  if (stats_out) *stats_out = stats;
  return out;
}

double rmsError(const std::vector<RdmData>& rdms) {
  double sum = 0.0;
  size_t n = 0;
  for (const RdmData& r : rdms) {
    for (int j = 0; j < kSize; ++j)
      for (int i = 0; i < kSize; ++i, ++n) sum += std::pow(faceTexel(r, i, j) - truth(i, j), 2.0);
  }
  return std::sqrt(sum / double(n));
}

// The mean |difference| of the same texel in blocks side by side (x + 1): the border a viewer
// crosses from one block's map to the next.
double borderDifference(const std::vector<RdmData>& rdms) {
  double sum = 0.0;
  size_t n = 0;
  for (int x = 0; x + 1 < kWall; ++x) {
    for (int z = 0; z < kWall; ++z) {
      const RdmData& a = rdms[size_t(x * kWall + z)];
      const RdmData& b = rdms[size_t((x + 1) * kWall + z)];
      for (int j = 0; j < kSize; ++j)
        for (int i = 0; i < kSize; ++i, ++n)
          sum += std::abs(faceTexel(a, i, j) - faceTexel(b, i, j));
    }
  }
  return sum / double(n);
}

TEST(Denoise, NoiseOnAFlatWallFallsAndTheBlocksComeTogether) {
  const std::vector<RdmData> noisy = wall(1);
  DenoiseStats stats;
  const std::vector<RdmData> blocks = denoised(noisy, DenoiseSettings{}, &stats);
  DenoiseSettings tile_settings;
  tile_settings.across_slots = false;
  const std::vector<RdmData> tile = denoised(noisy, tile_settings);
  // Gaussian noise of 0.2 on a truth of 1 to 1.75: the filter averages tens of taps (the
  // RMS error falls 2.4-fold, the border difference 2.6-fold, at the default colour sigma).
  const double before = rmsError(noisy), after = rmsError(blocks), after_tile = rmsError(tile);
  EXPECT_NEAR(before, kNoise, 0.02);
  EXPECT_LT(after, before / 2.0) << after;
  EXPECT_LT(after, after_tile) << "the neighbouring blocks' texels add independent samples";
  // Two independent noisy blocks differ by 2 / sqrt(pi) * 0.2 = 0.23 on average. Filtered
  // with each other's texels, the border difference falls as the noise does; a per-tile
  // filter leaves each block its own residue, a step at every border.
  const double border_before = borderDifference(noisy), border_after = borderDifference(blocks);
  const double border_tile = borderDifference(tile);
  EXPECT_NEAR(border_before, 2.0 / std::sqrt(M_PI) * kNoise, 0.02);
  EXPECT_LT(border_after, border_before / 2.0);
  EXPECT_LT(border_after, 0.75 * border_tile) << border_after << " vs " << border_tile;
  EXPECT_EQ(stats.rdms, noisy.size());
  EXPECT_EQ(stats.texels, noisy.size() * kSize * kSize);
  EXPECT_EQ(stats.filtered, stats.texels);
  EXPECT_LT(stats.relativeErrorAfter(), stats.relativeErrorBefore() / 2.0);
}

TEST(Denoise, KeepsDepthStepsColourEdgesAndTheDepthItself) {
  // One block: left half a near bright surface (Z 2, radiance 10), right half a far dim one
  // (Z 50, radiance 1), noise 1 % of each.
  std::mt19937 rng(7);
  RdmData rdm = wallBlock(0, 0, rng, 0.0f);
  std::normal_distribution<float> gauss(0.0f, 1.0f);
  for (int j = 0; j < kSize; ++j) {
    for (int i = 0; i < kSize; ++i) {
      const size_t p = size_t(kSize + j) * size_t(2 * kSize) + size_t(i);
      const bool near = i < kSize / 2;
      const float value = near ? 10.0f : 1.0f;
      for (int c = 0; c < 3; ++c) {
        rdm.image.pixels[p * 4 + size_t(c)] = value * (1.0f + 0.01f * gauss(rng));
        rdm.stderr_rgb[p * 3 + size_t(c)] = 0.01f * value;
      }
      rdm.image.pixels[p * 4 + 3] = near ? 2.0f : 50.0f;
    }
  }
  const RdmData out = denoised({rdm}, DenoiseSettings{})[0];
  for (int j = 0; j < kSize; ++j) {
    for (int i = 0; i < kSize; ++i) {
      const float expected = i < kSize / 2 ? 10.0f : 1.0f;
      EXPECT_NEAR(faceTexel(out, i, j), expected, 0.05f * expected) << i << ", " << j;
    }
  }
  for (size_t p = 3; p < rdm.image.pixels.size(); p += 4)
    ASSERT_EQ(out.image.pixels[p], rdm.image.pixels[p]);
}

TEST(Denoise, LeavesTexelsBelowTheNoiseFloorAndNearSurfacesOfOtherBlocksAlone) {
  std::mt19937 rng(3);
  std::vector<RdmData> rdms{wallBlock(0, 0, rng, 0.0f), wallBlock(1, 0, rng, 0.0f)};
  // No error at all: bit for bit as baked.
  std::vector<RdmData> out = denoised(rdms, DenoiseSettings{});
  EXPECT_EQ(out[0].image.pixels, rdms[0].image.pixels);
  EXPECT_EQ(out[0].stderr_rgb, rdms[0].stderr_rgb);
  // Both see a surface 0.5 units away, each a different radiance with some noise: one unit
  // of origin offset is ~5 texels of parallax at S = 8, so the other block's texels are far
  // off in direction and do not pull the value over.
  for (size_t b = 0; b < 2; ++b) {
    for (size_t p = 0; p < rdms[b].image.pixels.size() / 4; ++p) {
      if (rdms[b].image.pixels[p * 4 + 3] == 0.0f) continue;
      for (int c = 0; c < 3; ++c) {
        rdms[b].image.pixels[p * 4 + size_t(c)] = b == 0 ? 1.0f : 1.3f;
        rdms[b].stderr_rgb[p * 3 + size_t(c)] = 0.1f;
      }
      rdms[b].image.pixels[p * 4 + 3] = 0.5f;
    }
  }
  out = denoised(rdms, DenoiseSettings{});
  EXPECT_NEAR(faceTexel(out[0], 3, 3), 1.0f, 0.01f);
  EXPECT_NEAR(faceTexel(out[1], 3, 3), 1.3f, 0.01f);
}

TEST(Denoise, WithoutTheDerivedWindowADerivedLevelTakesOtherBlocksOnly) {
  // A level-2 block alone, prefiltered, derived_window off: nothing is averaged and the block
  // is as baked; with the window (the default, or a naive bake) it is filtered.
  std::mt19937 rng(11);
  RdmData rdm = wallBlock(0, 0, rng);
  rdm.id.level = 2;
  DenoiseSettings blocks_only;
  blocks_only.derived_window = false;
  EXPECT_EQ(denoised({rdm}, blocks_only)[0].image.pixels, rdm.image.pixels);
  EXPECT_LT(rmsError(denoised({rdm}, DenoiseSettings{})), rmsError({rdm}) / 1.8);  // 2.0 measured
  DenoiseSettings naive = blocks_only;
  naive.prefiltered = false;
  EXPECT_LT(rmsError(denoised({rdm}, naive)), rmsError({rdm}) / 1.8);
  // With its neighbours, a derived level does average the other blocks' texels.
  std::vector<RdmData> level2 = wall(12);
  for (RdmData& r : level2) r.id.level = 2;
  EXPECT_LT(rmsError(denoised(level2, blocks_only)), rmsError(level2) / 1.5);
}

TEST(Denoise, NeighboursFromAContextGiveTheSameResultAsNeighboursInTheSource) {
  const std::vector<RdmData> all = wall(5);
  const std::vector<RdmData> whole = denoised(all, DenoiseSettings{});
  // The first two blocks on their own, their neighbours in a second source (an incremental
  // job's kept RDMs).
  const std::vector<RdmData> own(all.begin(), all.begin() + 2);
  const std::vector<RdmData> kept(all.begin() + 2, all.end());
  auto spill = RdmSpill::create(spillDir());
  ASSERT_TRUE(spill.ok());
  DenoiseStats stats;
  const MemoryRdmSource context(kept);
  ASSERT_TRUE(denoiseRdms(MemoryRdmSource(own), &context, **spill, DenoiseSettings{}, 1, stats));
  ASSERT_EQ((*spill)->ids().size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    ASSERT_TRUE((*spill)->visit(i, [&](const RdmData& d) {
      EXPECT_EQ(d.id, whole[i].id);
      EXPECT_EQ(d.image.pixels, whole[i].image.pixels);
    }));
  }
}

TEST(Denoise, PlaneNeighboursAreTheFourSlotsBesideAFace) {
  const glm::ivec3 s(5, 6, 7);
  const auto x = planeNeighbourSlots(s, 0);
  EXPECT_EQ(x[0], glm::ivec3(5, 5, 7));
  EXPECT_EQ(x[1], glm::ivec3(5, 7, 7));
  EXPECT_EQ(x[2], glm::ivec3(5, 6, 6));
  EXPECT_EQ(x[3], glm::ivec3(5, 6, 8));
  const auto y = planeNeighbourSlots(s, 1);
  EXPECT_EQ(y[0], glm::ivec3(4, 6, 7));
  EXPECT_EQ(y[3], glm::ivec3(5, 6, 8));
  const auto z = planeNeighbourSlots(s, 2);
  EXPECT_EQ(z[1], glm::ivec3(6, 6, 7));
  EXPECT_EQ(z[2], glm::ivec3(5, 5, 7));
}

}  // namespace
}  // namespace rdm
