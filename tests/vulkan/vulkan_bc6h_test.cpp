// The Vulkan BC6H encoder (rdm/vulkan/vulkan_bc6h.h, docs/bc6h.md) gives the CPU encoder's
// blocks bit for bit: on random HDR images with every kind of input the contract handles
// (zeros, NaN, infinities, negatives, float denormals, values at and beyond 65504, half
// subnormals, constant and two-colour blocks, random bit patterns), in every mode set, over
// several dispatches, and on a baked atlas page. Without a Vulkan device the tests fail
// (test_requirements.h); CI always has lavapipe.
#include "rdm/vulkan/vulkan_bc6h.h"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "rdm/atlas/atlas.h"
#include "rdm/bake/bake.h"
#include "rdm/image/bc6h.h"
#include "rdm/scene/scene.h"
#include "rdm/scene/world.h"
#include "vulkan_bake_support.h"

namespace rdm {
namespace {

using test::vulkanMissing;

// One encoder per process: device and pipeline creation cost more than most tests' images.
VulkanBc6hEncoder* encoder() {
  static std::unique_ptr<VulkanBc6hEncoder> made = [] {
    auto e = VulkanBc6hEncoder::create("");
    if (!e) ADD_FAILURE() << e.error();
    return e ? std::move(*e) : nullptr;
  }();
  return made.get();
}

#define RDM_REQUIRE_ENCODER()                                                               \
  RDM_TEST_REQUIRE(vulkanMissing().empty(), "a Vulkan device (" << vulkanMissing() << ")"); \
  ASSERT_NE(encoder(), nullptr)

// Index of the first block where `a` and `b` differ, or -1.
long firstDifference(const Bc6hImage& a, const Bc6hImage& b) {
  if (a.blocks.size() != b.blocks.size()) return 0;
  for (size_t i = 0; i < a.blocks.size(); ++i)
    if (a.blocks[i] != b.blocks[i]) return long(i / kBc6hBlockBytes);
  return -1;
}

void expectSameBlocks(const Image& image, Bc6hModeSet modes) {
  Expected<Bc6hImage> cpu = encodeBc6h(image, {modes, 0});
  ASSERT_TRUE(cpu.ok()) << cpu.error();
  Expected<Bc6hImage> gpu = encoder()->encode(image, modes);
  ASSERT_TRUE(gpu.ok()) << gpu.error();
  EXPECT_EQ(gpu->width, image.width);
  EXPECT_EQ(gpu->height, image.height);
  const long at = firstDifference(*cpu, *gpu);
  EXPECT_EQ(at, -1) << "block " << at << " of " << cpu->blocks.size() / kBc6hBlockBytes
                    << " (mode set " << int(modes) << ")";
}

// The value of one texel channel for block kind `kind`: HDR noise over 14 decades, smooth
// ramps, constants, zeros, the contract's special inputs, values near 65504, half subnormals,
// two colours, and any 32-bit pattern.
float texelValue(int kind, int t, int c, float constant, std::mt19937& rng) {
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  const float specials[] = {nan,      -nan,     inf,      -inf, -1.0f, -0.0f, 0.0f, 1e-40f,
                            65504.0f, 65519.0f, 65520.0f, 1e6f, 6e-8f, 3e-8f, 1.0f, 0.5f};
  switch (kind) {
    case 0:
      return std::pow(10.0f, 14.0f * unit(rng) - 9.0f);
    case 1:
      return constant * (1.0f + 0.1f * float(t % 4) + 0.05f * float(t / 4 + c));
    case 2:
      return constant;
    case 3:
      return 0.0f;
    case 4:
      return specials[rng() % 16];
    case 5:
      return 60000.0f + 6000.0f * unit(rng);
    case 6:
      return 1e-7f * unit(rng);
    case 7:
      return t % 4 < 2 ? constant : 3.0f * constant * (1.0f + 0.2f * float(c));
    default:
      return std::bit_cast<float>(uint32_t(rng()));
  }
}

// Top half: each block a kind in turn (lanes of a SIMD vector take different paths); bottom
// half: all HDR noise (every lane takes the longest path, the worst case for lavapipe's loop
// limit). Four channels, the fourth garbage (not encoded).
Image randomHdrImage(int width, int height, uint32_t seed) {
  std::mt19937 rng(seed);
  Image image(width, height, 4);
  const int wide = width / 4;
  for (int by = 0; by < height / 4; ++by)
    for (int bx = 0; bx < wide; ++bx) {
      const int kind = by < height / 8 ? (by * wide + bx) % 9 : 0;
      const float constant = std::pow(10.0f, 8.0f * float(rng() % 1000) / 1000.0f - 5.0f);
      for (int t = 0; t < 16; ++t) {
        for (int c = 0; c < 3; ++c)
          image.at(bx * 4 + t % 4, by * 4 + t / 4, c) = texelValue(kind, t, c, constant, rng);
        image.at(bx * 4 + t % 4, by * 4 + t / 4, 3) = std::bit_cast<float>(uint32_t(rng()));
      }
    }
  return image;
}

TEST(VulkanBc6h, RandomHdrBlocksMatchTheCpuInEveryModeSet) {
  RDM_REQUIRE_ENCODER();
  std::printf("[ bc6h ] device '%s', samples BC6H_UFLOAT: %s\n", encoder()->device().name.c_str(),
              encoder()->samplesBc6h() ? "yes" : "no");
  expectSameBlocks(randomHdrImage(128, 64, 1), Bc6hModeSet::kAll);
  expectSameBlocks(randomHdrImage(64, 32, 2), Bc6hModeSet::kOneRegion);
  expectSameBlocks(randomHdrImage(64, 32, 3), Bc6hModeSet::kMode11);
}

// 130 x 130 blocks: more than one dispatch's band (16,384 blocks), so two dispatches.
TEST(VulkanBc6h, ImagesLargerThanABandMatchTheCpu) {
  RDM_REQUIRE_ENCODER();
  Image image(520, 520, 3);
  for (int y = 0; y < 520; ++y)
    for (int x = 0; x < 520; ++x)
      for (int c = 0; c < 3; ++c)
        image.at(x, y, c) = std::exp(0.02f * float(x) - 0.01f * float(y) + 0.3f * float(c));
  const uint64_t before = encoder()->info().dispatches;
  expectSameBlocks(image, Bc6hModeSet::kAll);
  EXPECT_EQ(encoder()->info().dispatches - before, 2u);
}

// Page 0 of chess's bc6h atlas (S <= 16, 4 spp) as writeAtlasOutputs encodes it.
TEST(VulkanBc6h, ChessAtlasPageMatchesTheCpu) {
  RDM_REQUIRE_ENCODER();
  const Scene scene = builtinScene("chess").value();
  BakeSettings settings = scene.bake;
  settings.spp = 4, settings.max_hemisphere = 16;
  const std::vector<RdmData> rdms = bakeScene(buildWorld(scene), settings, BakeOptions{}).rdms;
  std::vector<RdmId> ids;
  for (const RdmData& d : rdms) ids.push_back(d.id);
  const AtlasLayout layout = packCanonical(ids, storedFacesOf(rdms), RadianceFormat::kBc6h);
  std::vector<Image> pages = assembleAtlas(layout, rdms);
  ASSERT_FALSE(pages.empty());
  padSmallTiles(layout, 0, pages[0]);
  std::printf("[ bc6h ] chess page 0: %d x %d\n", pages[0].width, pages[0].height);
  EXPECT_GE(pages[0].width * pages[0].height, 16 * 4096);  // over 4,096 blocks (272 x 252)
  expectSameBlocks(pages[0], Bc6hModeSet::kAll);
}

// The device encoder refuses what the CPU's refuses, with the same field.
TEST(VulkanBc6h, RefusesWhatTheCpuRefuses) {
  RDM_REQUIRE_ENCODER();
  for (const Image& bad : {Image(6, 4, 3), Image(4, 2, 3), Image(4, 4, 1)}) {
    Expected<Bc6hImage> cpu = encodeBc6h(bad);
    Expected<Bc6hImage> gpu = encoder()->encode(bad);
    ASSERT_FALSE(cpu.ok());
    ASSERT_FALSE(gpu.ok());
    EXPECT_EQ(gpu.status().field(), cpu.status().field());
  }
}

// lavapipe (Mesa 22.3.6) reports VK_FORMAT_BC6H_UFLOAT_BLOCK sampled and linearly filtered
// with optimal tiling (docs/bc6h.md); other devices are only printed.
TEST(VulkanBc6h, ReportsWhetherTheDeviceSamplesBc6h) {
  RDM_REQUIRE_ENCODER();
  const std::string& name = encoder()->device().name;
  std::printf("[ bc6h ] '%s' samples BC6H_UFLOAT_BLOCK: %d\n", name.c_str(),
              int(encoder()->samplesBc6h()));
  if (name.find("llvmpipe") == std::string::npos)
    GTEST_SKIP() << "the expected answer is known only for lavapipe, not '" << name << "'";
  EXPECT_TRUE(encoder()->samplesBc6h());
}

}  // namespace
}  // namespace rdm
