// Glass in the path tracer (rdm/trace/glass.h, docs/spec.md section 5 "Glass"): the interface
// formulas, a glass block in a white furnace keeps every path's energy, light passes a
// window into a closed room, and a scene without glass runs none of it.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "rdm/bake/render.h"
#include "rdm/trace/glass.h"
#include "rdm/trace/integrator.h"
#include "rdm/transport/rdm_shared_cpp.h"
#include "test_scenes.h"

namespace rdm {
namespace {

TEST(Glass, FresnelAndSnellAtAnInterface) {
  // Normal incidence from air into n = 1.5: ((1.5 - 1) / (1.5 + 1))^2 = 0.04, both ways.
  EXPECT_NEAR(shared::fresnelDielectric(1.0f, 1.0f / 1.5f), 0.04f, 1e-6f);
  EXPECT_NEAR(shared::fresnelDielectric(1.0f, 1.5f), 0.04f, 1e-6f);
  // Past the critical angle (sin 41.8 deg) inside the glass: total internal reflection.
  EXPECT_EQ(shared::fresnelDielectric(std::cos(0.8f), 1.5f), 1.0f);
  EXPECT_LT(shared::fresnelDielectric(std::cos(0.7f), 1.5f), 1.0f);
  // Snell: sin t = eta sin i, on the far side of the interface.
  const glm::vec3 n(0.0f, 0.0f, 1.0f);
  const glm::vec3 d = glm::normalize(glm::vec3(std::sin(0.6f), 0.0f, -std::cos(0.6f)));
  const glm::vec3 t = shared::refractDirection(d, n, 1.0f / 1.5f);
  EXPECT_NEAR(t.x, std::sin(0.6f) / 1.5f, 1e-6f);
  EXPECT_LT(t.z, 0.0f);
  EXPECT_NEAR(glm::length(t), 1.0f, 1e-6f);
}

Scene glassFurnace() {
  Scene s = test::uniformSkyScene(3, 3, 3, 1.0);
  s.palette = {{{255, 255, 255}, 0, 0, 0, 1.0, 1.5}};
  s.blocks["glass"] = test::blockFrom([](int x, int y, int z) {
    return x >= 4 && x < 12 && y >= 4 && y < 12 && z >= 4 && z < 12 ? 1 : 0;
  });
  s.placements = {{{1, 1, 1}, "glass", 0}};
  return s;
}

TEST(Glass, AClearGlassBlockInAWhiteFurnaceKeepsEveryPathsEnergy) {
  // White glass (tint 1, transmission 1) under a uniform sky of 1: each path reflects or
  // refracts with weight 1 until it leaves, so it returns exactly 1 unless it meets the glass
  // more than kMaxGlassEvents times (total internal reflection). Measured: 1.00000. Bounds:
  // every path <= 1, the mean above 0.99, and every path met the glass.
  const Scene s = glassFurnace();
  const VoxelWorld world = buildWorld(s);
  ASSERT_TRUE(hasGlass(world));
  PathStats stats;
  double sum = 0.0;
  const int kPaths = 20000;
  for (int i = 0; i < kPaths; ++i) {
    const uint32_t key = shared::pathKey(7, 0, 0, uint32_t(i), 0);
    const glm::vec3 target(21.0f + 6.0f * shared::randomUniform(key, 0, 20),
                           21.0f + 6.0f * shared::randomUniform(key, 0, 21), 24.0f);
    const glm::vec3 origin(20.0f + 16.0f * shared::randomUniform(key, 0, 22), 30.0f, 2.0f);
    const glm::vec3 l = tracePath<false, false>(world, 16, origin, glm::normalize(target - origin),
                                                key, PathOrigin::kCamera, stats);
    ASSERT_LE(l.g, 1.0f + 1e-6f);
    sum += l.g;
  }
  std::printf("[ glass ] furnace mean %.5f over %d paths, %.2f rays a path\n", sum / kPaths, kPaths,
              double(stats.rays) / kPaths);
  EXPECT_GT(sum / kPaths, 0.99);
  // Every path enters the glass: its first segment, the walk inside, the one after it.
  EXPECT_GE(stats.rays, uint64_t(3 * kPaths));
}

// A closed white room of one block with a 5 x 5 window in its +x wall, lit by the sky and a sun
// shining in through the window; `window` is the palette index in the window (0: open).
Scene roomWithWindow(int window) {
  Scene s = test::uniformSkyScene(1, 1, 1, 0.3);
  s.palette = {{{200, 200, 200}, 7, 0, 0}, {{255, 255, 255}, 0, 0, 0, 1.0, 1.5}};
  s.blocks["room"] = test::blockFrom([window](int x, int y, int z) {
    const bool wall = x == 0 || x == 15 || y == 0 || y == 15 || z == 0 || z == 15;
    if (x == 15 && y >= 6 && y < 11 && z >= 6 && z < 11) return window;
    return wall ? 1 : 0;
  });
  s.placements = {{{0, 0, 0}, "room", 0}};
  s.sun = Sun{{1.0, 0.6, 0.1}, {3.0, 3.0, 3.0}, 0.27};
  s.cameras = {Camera{{0.5, 0.8, 0.5}, {0.45, 0.0, 0.5}, 100.0, ""}};  // block units
  s.bake.max_bounces = 4;
  return s;
}

double meanRender(const Scene& s) {
  RenderOptions o;
  o.width = 48, o.height = 48, o.spp = 32, o.threads = 2;
  const Expected<Image> image = renderReference(s, buildWorld(s), o);
  EXPECT_TRUE(image.ok()) << image.error();
  if (!image.ok()) return -1.0;
  double sum = 0.0;
  for (float v : image->pixels) sum += v;
  return sum / double(image->pixels.size());
}

TEST(Glass, LightPassesAWindowIntoAClosedRoom) {
  // Measured 2026-12-07 (48 x 48, 32 spp): open window 0.0287, glass 0.0247 (0.86x: a slab
  // keeps (1 - F)^2, 0.92 at normal incidence and about 0.84 averaged over the hemisphere),
  // opaque wall 0 (the room is closed). Bounds: glass between 0.75x and 0.95x of the open
  // window; the opaque room exactly dark.
  const double open = meanRender(roomWithWindow(0));
  const double glass = meanRender(roomWithWindow(2));
  const double wall = meanRender(roomWithWindow(1));
  std::printf("[ glass ] room mean: open %.4f, glass %.4f, opaque %.4f\n", open, glass, wall);
  EXPECT_GT(glass, 0.75 * open);
  EXPECT_LT(glass, 0.95 * open);
  EXPECT_EQ(wall, 0.0);
}

}  // namespace
}  // namespace rdm
