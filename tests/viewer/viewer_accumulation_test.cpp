// The viewer's anti-aliasing by accumulation (viewer/renderer/frame_accumulator.h): the
// jitter sequence and the restart rules on the CPU, and the renderer's averaged chess frame
// against its single frame on lavapipe. Built with the viewer only.
#include <gtest/gtest.h>

#ifdef RDM_VIEWER_BINARY
#include <algorithm>
#include <cmath>
#include <set>

#include "frame_accumulator.h"
#include "rdm/atlas/atlas.h"
#include "rdm/bake/bake.h"
#include "rdm/scene/scene.h"
#include "rdm/scene/world.h"
#include "renderer.h"
#include "test_requirements.h"

namespace rdm::viewer {
namespace {

TEST(ViewerAccumulation, JitterStartsAtTheCentreAndCoversThePixelEvenly) {
  EXPECT_EQ(pixelJitter(0), glm::vec2(0.0f));
  std::set<std::pair<float, float>> seen;
  glm::vec2 sum(0.0f);
  int quadrant[4] = {0, 0, 0, 0};
  for (int k = 1; k <= 16; ++k) {
    const glm::vec2 j = pixelJitter(k);
    ASSERT_GE(j.x, -0.5f);
    ASSERT_LT(j.x, 0.5f);
    ASSERT_GE(j.y, -0.5f);
    ASSERT_LT(j.y, 0.5f);
    EXPECT_TRUE(seen.insert({j.x, j.y}).second) << k;
    sum += j;
    ++quadrant[(j.x >= 0.0f ? 1 : 0) + (j.y >= 0.0f ? 2 : 0)];
  }
  // Halton (2, 3): the 16 points average within 0.05 of the centre and fill each quadrant.
  EXPECT_LT(std::abs(sum.x / 16.0f), 0.05f);
  EXPECT_LT(std::abs(sum.y / 16.0f), 0.05f);
  for (int q : quadrant) EXPECT_GE(q, 3);
}

TEST(ViewerAccumulation, StillViewAveragesUpToTheLimitAndEveryChangeRestarts) {
  const Camera camera = builtinScene("chess").value().cameras[0];
  Camera moved = camera;
  moved.position.x += 0.01;
  FrameAccumulator a;
  for (int i = 0; i < 3; ++i) {  // limit 1: every frame afresh, at the centre
    const AccumulationStep s = a.next(camera, 7, 1);
    EXPECT_TRUE(s.shade);
    EXPECT_EQ(s.weight, 1.0f);
    EXPECT_EQ(s.jitter, glm::vec2(0.0f));
    EXPECT_FALSE(a.refining());
  }
  a.setLimit(4);
  for (int i = 0; i < 4; ++i) {
    const AccumulationStep s = a.next(camera, 7, 1);
    EXPECT_TRUE(s.shade);
    EXPECT_FLOAT_EQ(s.weight, 1.0f / float(i + 1));
    EXPECT_EQ(s.jitter, pixelJitter(i));
    EXPECT_EQ(a.refining(), i < 3);
  }
  EXPECT_FALSE(a.next(camera, 7, 1).shade);  // complete: only re-presented
  EXPECT_EQ(a.frames(), 4);
  EXPECT_EQ(a.next(moved, 7, 1).weight, 1.0f);  // the camera moved
  EXPECT_EQ(a.next(moved, 3, 1).weight, 1.0f);  // the terms changed
  EXPECT_EQ(a.next(moved, 3, 1).weight, 0.5f);
  a.invalidate();  // scene, atlas or size changed
  EXPECT_EQ(a.next(moved, 3, 1).weight, 1.0f);
  for (int i = 0; i < 3; ++i) {  // interactive resolution: never averaged
    EXPECT_EQ(a.next(moved, 3, 2).weight, 1.0f);
    EXPECT_FALSE(a.refining());
  }
}

// A pixel at least 40 / 255 darker than all eight neighbours (mean of R, G, B): on chess
// these are sub-pixel slivers of the pieces' steps, where one sample per pixel shows the
// sliver's reflection of the piece at full weight.
int isolatedDarkPixels(const Image8& image) {
  auto level = [&](int x, int y) {
    const uint8_t* p = &image.pixels[(size_t(y) * image.width + x) * 3];
    return (int(p[0]) + p[1] + p[2]) / 3;
  };
  int n = 0;
  for (int y = 1; y + 1 < image.height; ++y)
    for (int x = 1; x + 1 < image.width; ++x) {
      int darkest_neighbour = 255;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx)
          if (dx || dy) darkest_neighbour = std::min(darkest_neighbour, level(x + dx, y + dy));
      n += level(x, y) < darkest_neighbour - 40 ? 1 : 0;
    }
  return n;
}

LoadedAtlas bakedChess(const Scene& scene) {
  BakeSettings settings = scene.bake;
  settings.spp = 4, settings.max_hemisphere = 16;
  BakeResult result = bakeScene(buildWorld(scene), settings, BakeOptions{});
  std::vector<RdmId> ids;
  for (const RdmData& d : result.rdms) ids.push_back(d.id);
  LoadedAtlas atlas;
  atlas.layout = packCanonical(ids, storedFacesOf(result.rdms));
  atlas.pages = assembleAtlas(atlas.layout, result.rdms);
  return atlas;
}

// Item 19 of the first-hour issue: the single chess frame at 1280 x 720 has isolated dark
// pixels along the pieces' edges; 16 averaged frames have at most a quarter as many, and
// the average changes the image only at edges (mean |difference| <= 1.5 / 255).
TEST(ViewerAccumulation, AveragedChessFrameLosesTheIsolatedDarkPixels) {
  auto context = VulkanContext::create({});
  RDM_TEST_REQUIRE(context.ok(),
                   "no Vulkan device: " << (context ? std::string() : context.error()));
  const Scene scene = builtinScene("chess").value();
  auto renderer = Renderer::create(**context, {1280, 720, 2048});
  ASSERT_TRUE(renderer.ok()) << renderer.error();
  Renderer& r = **renderer;
  ASSERT_TRUE(r.setScene(scene).ok());
  ASSERT_TRUE(r.setAtlas(bakedChess(scene)).ok());
  ASSERT_TRUE(r.renderFrame(scene.cameras[0], kTermBase).ok());
  const Image8 single = r.readLdr().value();
  r.setAccumulationLimit(16);
  for (int i = 0; i < 16; ++i) ASSERT_TRUE(r.renderFrame(scene.cameras[0], kTermBase).ok());
  EXPECT_EQ(r.accumulation().frames(), 16);
  EXPECT_FALSE(r.accumulation().refining());
  const Image8 averaged = r.readLdr().value();
  ASSERT_TRUE(r.renderFrame(scene.cameras[0], kTermBase).ok());  // complete: re-presented
  EXPECT_EQ(r.readLdr().value().pixels, averaged.pixels);
  const int before = isolatedDarkPixels(single), after = isolatedDarkPixels(averaged);
  std::printf("[ viewer ] isolated dark pixels: %d in one frame, %d in 16 averaged\n", before,
              after);
  EXPECT_GE(before, 4);  // the defect is there to remove
  EXPECT_LE(4 * after, before);
  double diff = 0.0;
  for (size_t i = 0; i < single.pixels.size(); ++i)
    diff += std::abs(int(single.pixels[i]) - int(averaged.pixels[i]));
  EXPECT_LE(diff / double(single.pixels.size()), 1.5);
  const Image hdr = r.readHdr().value();  // a copy: the Expected is a temporary
  for (float v : hdr.pixels) ASSERT_TRUE(std::isfinite(v) && v >= 0.0f);
}

}  // namespace
}  // namespace rdm::viewer
#endif  // RDM_VIEWER_BINARY
