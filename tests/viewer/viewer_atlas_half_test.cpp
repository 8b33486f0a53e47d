// The viewer at scale (issue 35 item 4): the atlas lives on the device at half precision
// (RGBA16F) with no CPU copy, pages stream from the files strip by strip, and every slot's
// block mesh goes into one draw. Built with the viewer only.
#include <gtest/gtest.h>

#ifdef RDM_VIEWER_BINARY
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "atlas_texture.h"
#include "rdm/atlas/atlas.h"
#include "rdm/bake/bake.h"
#include "rdm/scene/scene.h"
#include "rdm/scene/world.h"
#include "renderer.h"
#include "scene_gpu.h"
#include "test_requirements.h"

namespace rdm::viewer {
namespace {

#define REQUIRE_CONTEXT(context)   \
  RDM_TEST_REQUIRE((context).ok(), \
                   "no Vulkan device: " << ((context).ok() ? std::string() : (context).error()))

TEST(ViewerAtlasHalf, ConversionRoundsToNearestAndClampsToHalfsRange) {
  EXPECT_EQ(atlasHalf(1.0f), 0x3c00);
  EXPECT_EQ(atlasHalf(0.0f), 0x0000);
  EXPECT_EQ(atlasFloat(atlasHalf(1e6f)), kAtlasHalfMax);  // a sun-lit mirror: clamped, finite
  EXPECT_EQ(atlasFloat(atlasHalf(-1e6f)), -kAtlasHalfMax);
  EXPECT_EQ(atlasFloat(atlasHalf(1.0e4f)), 1.0e4f);  // the sky depth is exact
  // Half's normal range: relative error at most 2^-11 (round to nearest).
  for (float v = 6.2e-5f; v < 65000.0f; v *= 1.37f) {
    const float back = atlasFloat(atlasHalf(v));
    ASSERT_LE(std::abs(back - v), v * std::ldexp(1.0f, -11)) << v;
  }
}

TEST(ViewerAtlasHalf, DepthMaskAnswersForRectsAndFollowsCopies) {
  AtlasDepthMask a;
  a.reset(2, 130, 20);
  Image texels(3, 2, 4);
  texels.at(2, 1, 3) = 0.5f;  // one texel with depth, at (66, 11) of layer 1
  a.write(1, 64, 10, texels);
  EXPECT_TRUE(a.any(1, 64, 10, 3, 2));
  EXPECT_TRUE(a.any(1, 66, 11, 1, 1));
  EXPECT_FALSE(a.any(1, 64, 10, 2, 2));
  EXPECT_FALSE(a.any(0, 0, 0, 130, 20));
  EXPECT_FALSE(a.any(1, 120, 0, 20, 20));  // outside: nothing
  AtlasDepthMask b;
  b.reset(2, 200, 40);
  b.copyFrom(a, 1, 130, 20);
  EXPECT_TRUE(b.any(1, 66, 11, 1, 1));
  EXPECT_EQ(b.bytes(), size_t(2) * 4 * 40 * 8);
  a.clear(1, 60, 8, 10, 10);
  EXPECT_FALSE(a.any(1, 0, 0, 130, 20));
}

Image patternPage(int w, int h, float scale) {
  Image page(w, h, 4);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 4; ++c)
        page.at(x, y, c) = c == 3 ? ((x + y) % 3 == 0 ? 0.0f : 0.25f * float(x + 1))
                                  : scale * float((x * 7 + y * 13 + c * 5) % 1009) / 1009.0f;
  return page;
}

// The device image is RGBA16F, 8 bytes a texel; it holds the pages rounded to half, the
// depth mask their Z != 0; a delta changes only its rect; growing past the image copies the
// old pages on the device.
TEST(ViewerAtlasHalf, DeviceImageIsHalfAndDeltasAndGrowthWork) {
  auto context = VulkanContext::create({});
  REQUIRE_CONTEXT(context);
  const Image page0 = patternPage(64, 48, 3.0f), page1 = patternPage(40, 64, 7e4f);
  auto atlas = AtlasTexture::create(**context, std::vector<Image>{page0, page1});
  ASSERT_TRUE(atlas.ok()) << atlas.error();
  AtlasTexture& a = **atlas;
  EXPECT_EQ(a.format(), VK_FORMAT_R16G16B16A16_SFLOAT);
  EXPECT_EQ(a.texelBytes(), 8u);
  EXPECT_EQ(a.width(), 64);
  EXPECT_EQ(a.layers(), 2);
  EXPECT_EQ(a.deviceBytes(), size_t(64) * size_t(a.height()) * 2 * 8);
  for (int layer = 0; layer < 2; ++layer) {
    const Image& page = layer == 0 ? page0 : page1;
    auto back = a.readLayer(layer);
    ASSERT_TRUE(back.ok()) << back.error();
    for (int y = 0; y < page.height; ++y)
      for (int x = 0; x < page.width; ++x) {
        for (int c = 0; c < 4; ++c)
          ASSERT_EQ(back->at(x, y, c), atlasFloat(atlasHalf(page.at(x, y, c))))
              << layer << ": " << x << "," << y << "," << c;
        ASSERT_EQ(a.depthMask().any(layer, x, y, 1, 1), page.at(x, y, 3) != 0.0f);
      }
  }
  // A delta: exactly its rect changes.
  Image rect(6, 4, 4);
  std::fill(rect.pixels.begin(), rect.pixels.end(), 2.5f);
  ASSERT_TRUE(a.applyDelta({{1, 10, 20, rect}}).ok());
  auto after = a.readLayer(1);
  ASSERT_TRUE(after.ok());
  for (int y = 0; y < page1.height; ++y)
    for (int x = 0; x < page1.width; ++x) {
      const bool inside = x >= 10 && x < 16 && y >= 20 && y < 24;
      ASSERT_EQ(after->at(x, y, 0), inside ? 2.5f : atlasFloat(atlasHalf(page1.at(x, y, 0))));
    }
  EXPECT_FALSE(a.applyDelta({{1, 36, 0, rect}}).ok());  // leaves the 40-wide page
  // Growth past the image: a new image with a page more, the old pages copied on the device.
  auto grown = AtlasTexture::create(**context, std::vector<AtlasPage>{{64, 200}, {40, 64}, {8, 8}});
  ASSERT_TRUE(grown.ok()) << grown.error();
  ASSERT_TRUE((*grown)->copyPagesFrom(a).ok());
  auto g0 = (*grown)->readLayer(0), g1 = (*grown)->readLayer(1), g2 = (*grown)->readLayer(2);
  ASSERT_TRUE(g0.ok() && g1.ok() && g2.ok());
  for (int y = 0; y < 200; ++y)
    for (int x = 0; x < 64; ++x)
      for (int c = 0; c < 4; ++c) {
        const float want = y < 48 ? atlasFloat(atlasHalf(page0.at(x, y, c))) : 0.0f;
        ASSERT_EQ(g0->at(x, y, c), want) << x << "," << y;
      }
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 40; ++x) {
      ASSERT_EQ(g1->at(x, y, 0), after->at(x, y, 0));
      ASSERT_EQ((*grown)->depthMask().any(1, x, y, 1, 1), after->at(x, y, 3) != 0.0f);
    }
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) ASSERT_EQ(g2->at(x, y, 0), 0.0f);
}

struct BakedChess {
  std::vector<RdmData> rdms;
  AtlasLayout layout;
};

BakedChess bakeChess(const Scene& scene) {
  BakeSettings settings = scene.bake;
  settings.spp = 4, settings.max_hemisphere = 16;
  BakedChess out;
  out.rdms = bakeScene(buildWorld(scene), settings, BakeOptions{}).rdms;
  std::vector<RdmId> ids;
  for (const RdmData& d : out.rdms) ids.push_back(d.id);
  out.layout = packCanonical(ids, storedFacesOf(out.rdms));
  return out;
}

struct HdrDifference {
  double mean_relative = 0.0;  // sum |a - b| / sum |a| over every channel
  double max_abs = 0.0;
  double frac_over_1_percent = 0.0;  // pixels whose largest channel differs by > 1 %
};

HdrDifference compareHdr(const Image& reference, const Image& test) {
  HdrDifference d;
  double diff = 0.0, sum = 0.0;
  size_t over = 0;
  const size_t pixels = size_t(reference.width) * size_t(reference.height);
  for (size_t p = 0; p < pixels; ++p) {
    double worst = 0.0;
    for (int c = 0; c < 3; ++c) {
      const double a = reference.pixels[p * 3 + c], b = test.pixels[p * 3 + c];
      diff += std::abs(a - b), sum += std::abs(a);
      d.max_abs = std::max(d.max_abs, std::abs(a - b));
      worst = std::max(worst, std::abs(a - b) / std::max(std::abs(a), 1e-3));
    }
    over += worst > 0.01 ? 1 : 0;
  }
  d.mean_relative = diff / std::max(sum, 1e-30);
  d.frac_over_1_percent = double(over) / double(pixels);
  return d;
}

// Pages stream from the files strip by strip and land as readAtlasOutputs reads them, to
// the bit (a float texture; half-radiance files, so the tile exponents are undone per strip).
TEST(ViewerAtlasHalf, StreamedPagesMatchReadAtlasOutputs) {
  auto context = VulkanContext::create({});
  REQUIRE_CONTEXT(context);
  const Scene scene = builtinScene("chess").value();
  BakedChess baked = bakeChess(scene);
  // One bright RDM (a sun-lit mirror's values): its tiles need exponents at half.
  std::vector<float>& bright = baked.rdms[0].image.pixels;
  for (size_t i = 0; i < bright.size(); ++i) bright[i] *= i % 4 == 3 ? 1.0f : 1e6f;
  const std::string dir = testing::TempDir() + "/viewer_atlas_stream_" + std::to_string(getpid());
  std::filesystem::remove_all(dir);
  AtlasLayout layout = baked.layout;
  layout.radiance = RadianceFormat::kHalf;
  ASSERT_TRUE(writeAtlasOutputs(dir, layout, baked.rdms).ok());
  auto files = readAtlasOutputs(dir);
  ASSERT_TRUE(files.ok()) << files.error();
  int scaled = 0;
  for (const AtlasEntry& e : files->layout.entries)
    for (const FaceTile& t : e.faces) scaled += t.exponent > 0;
  EXPECT_GT(scaled, 0);
  auto read_layout = readAtlasLayout(dir);
  ASSERT_TRUE(read_layout.ok()) << read_layout.error();
  auto texture = AtlasTexture::create(**context, read_layout->pages, AtlasPrecision::kFloat);
  ASSERT_TRUE(texture.ok()) << texture.error();
  ASSERT_TRUE(loadAtlasPages(dir, *read_layout, **texture).ok());
  for (size_t p = 0; p < files->pages.size(); ++p) {
    auto layer = (*texture)->readLayer(int(p));
    ASSERT_TRUE(layer.ok());
    const Image& want = files->pages[p];
    for (int y = 0; y < want.height; ++y)
      for (int x = 0; x < want.width; ++x)
        for (int c = 0; c < 4; ++c)
          ASSERT_EQ(layer->at(x, y, c), want.at(x, y, c)) << p << ": " << x << "," << y;
  }
  EXPECT_FALSE(loadAtlasPages(dir + "_missing", *read_layout, **texture).ok());
  std::filesystem::remove_all(dir);
}

// The chess frame from the half atlas against the float atlas (the reference), both loaded
// from float32 files, every term on: the mean relative difference at most 1e-3, fewer than
// 1 % of the pixels off by more than 1 % (half's rounding is 2^-11 relative; only the
// march's depth comparisons can flip, at a few pixels).
TEST(ViewerAtlasHalf, ChessFromTheHalfAtlasMatchesTheFloatReference) {
  auto context = VulkanContext::create({});
  REQUIRE_CONTEXT(context);
  const Scene scene = builtinScene("chess").value();
  const BakedChess baked = bakeChess(scene);
  const std::string dir = testing::TempDir() + "/viewer_atlas_half_" + std::to_string(getpid());
  std::filesystem::remove_all(dir);
  ASSERT_TRUE(writeAtlasOutputs(dir, baked.layout, baked.rdms).ok());
  auto read_layout = readAtlasLayout(dir);
  ASSERT_TRUE(read_layout.ok()) << read_layout.error();
  Image reference, half;
  for (AtlasPrecision precision : {AtlasPrecision::kFloat, AtlasPrecision::kHalf}) {
    RendererOptions options;
    options.width = 320, options.height = 180, options.atlas_precision = precision;
    auto renderer = Renderer::create(**context, options);
    ASSERT_TRUE(renderer.ok()) << renderer.error();
    Renderer& r = **renderer;
    ASSERT_TRUE(r.setScene(scene).ok());
    ASSERT_TRUE(r.loadAtlas(dir, *read_layout).ok());
    EXPECT_EQ(r.atlas().format(), precision == AtlasPrecision::kHalf
                                      ? VK_FORMAT_R16G16B16A16_SFLOAT
                                      : VK_FORMAT_R32G32B32A32_SFLOAT);
    EXPECT_EQ(r.sceneData().draws.size(), 1u);  // every slot's mesh in one draw
    ASSERT_TRUE(r.renderFrame(scene.cameras[0], kTermDefault).ok());
    (precision == AtlasPrecision::kFloat ? reference : half) = r.readHdr().value();
  }
  const HdrDifference d = compareHdr(reference, half);
  std::printf(
      "[ viewer ] half vs float atlas, chess 320x180: mean relative %.2e, max |diff| %.3g, "
      "%.3f %% of pixels off by > 1 %%\n",
      d.mean_relative, d.max_abs, 100.0 * d.frac_over_1_percent);
  EXPECT_LE(d.mean_relative, 1e-3);
  EXPECT_LT(d.frac_over_1_percent, 0.01);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace rdm::viewer
#endif  // RDM_VIEWER_BINARY
