// traceVoxelStream against referenceWalk, bit for bit, on every SIMD target Highway compiled
// that this CPU runs (each has its own lane count), in streams that mix every kind of ray.
#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "rdm/scene/scene.h"
#include "rdm/trace/voxel_stream.h"
#include "test_scenes.h"

namespace rdm {
namespace {

using glm::ivec3;
using glm::vec3;

// Every field a caller of traceVoxels reads, and the hit time bit for bit.
::testing::AssertionResult sameAsReference(const VoxelWorld& w, const std::vector<FloatRay>& rays) {
  std::vector<TraceHit> hits(rays.size());
  std::vector<float> t(rays.size(), -1.0f);
  traceVoxelStream(w, rays, hits, t);
  for (size_t i = 0; i < rays.size(); ++i) {
    float t_ref = -1.0f;
    const TraceHit ref = detail::referenceWalk(w, rays[i], t_ref, NoSlotVisitor());
    const TraceHit& h = hits[i];
    const bool same = h.hit == ref.hit && h.voxel == ref.voxel && h.axis == ref.axis &&
                      h.palette == ref.palette && h.started_solid == ref.started_solid &&
                      (!ref.hit || std::memcmp(&t[i], &t_ref, sizeof(float)) == 0);
    if (same) continue;
    const FloatRay& r = rays[i];
    return ::testing::AssertionFailure()
           << "ray " << i << " of " << rays.size() << " o=" << r.o.x << "," << r.o.y << "," << r.o.z
           << " d=" << r.d.x << "," << r.d.y << "," << r.d.z << " hit " << h.hit << "/" << ref.hit
           << " voxel " << h.voxel.x << "," << h.voxel.y << "," << h.voxel.z << "/" << ref.voxel.x
           << "," << ref.voxel.y << "," << ref.voxel.z << " axis " << h.axis << "/" << ref.axis
           << " palette " << int(h.palette) << "/" << int(ref.palette) << " t " << t[i] << "/"
           << t_ref << " (" << voxelStreamTarget() << ")";
  }
  return ::testing::AssertionSuccess();
}

// Runs `check` once per SIMD target that Highway compiled and this CPU supports.
template <class Check>
void forEachTarget(Check check) {
  const std::vector<int64_t> targets = hwy::SupportedAndGeneratedTargets();
  ASSERT_FALSE(targets.empty());
  for (int64_t target : targets) {
    hwy::SetSupportedTargetsForTest(target);
    SCOPED_TRACE(hwy::TargetName(target));
    check();
  }
  hwy::SetSupportedTargetsForTest(0);
}

// Blocks of whole 4^3 bricks, empty, full or sparse, and empty slots between them. With
// `empty_octants`, about half of each block's 8^3 octants are empty as a whole, so the walk
// crosses them in one step.
VoxelWorld brickWorld(bool empty_octants = false) {
  Scene s = test::uniformSkyScene(4, 3, 4);
  s.palette.push_back({{200, 40, 40}, 3, 0, 0});
  std::mt19937 rng(21);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 4; ++i) {
        if (u(rng) < 0.3) continue;
        std::vector<int> kind(64);
        for (int& b : kind) b = u(rng) < 0.55 ? 0 : (u(rng) < 0.3 ? 1 : 2);
        std::vector<bool> octant_empty(8);
        for (size_t o = 0; o < 8; ++o) octant_empty[o] = empty_octants && u(rng) < 0.5;
        const std::string name = "k" + std::to_string(i + 4 * (j + 3 * k));
        s.blocks[name] = test::blockFrom([&](int x, int y, int z) {
          if (octant_empty[size_t(x / 8 + 2 * (y / 8) + 4 * (z / 8))]) return 0;
          const int b = kind[size_t(x / 4 + 4 * (y / 4) + 16 * (z / 4))];
          return b == 1 ? 1 + (x + y + z) % 2 : (b == 2 && u(rng) < 0.08 ? 2 : 0);
        });
        s.placements.push_back({{i, j, k}, name, int(u(rng) * 24) % 24});
      }
  return buildWorld(s);
}

// Rays of every kind the walk's rules single out, for a 64 x 48 x 64 grid: random ones,
// integer origins on voxel, brick and slot corners with equal direction components, rays in
// brick and slot planes (d = +-0), grazing rays, rays on and outside the grid's border, and
// irregular rays (which take referenceWalk inside the stream).
std::vector<FloatRay> everyKindOfRay() {
  std::vector<FloatRay> rays;
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.0f, 1.0f), dir(-1.0f, 1.0f);
  for (int i = 0; i < 6000; ++i) {
    const vec3 d(dir(rng), dir(rng), dir(rng));
    if (glm::length(d) < 0.05f) continue;
    rays.emplace_back(vec3(u(rng) * 80.0f - 8.0f, u(rng) * 60.0f - 6.0f, u(rng) * 80.0f - 8.0f),
                      glm::normalize(d));
  }
  std::uniform_int_distribution<int> pos(0, 16), comp(-3, 3);
  for (int i = 0; i < 6000; ++i) {
    const ivec3 d(comp(rng), comp(rng), comp(rng));
    if (d == ivec3(0)) continue;
    const int scale = i % 3 == 0 ? 4 : (i % 3 == 1 ? 1 : 16);
    const ivec3 o = glm::min(ivec3(pos(rng), pos(rng), pos(rng)) * scale, ivec3(64, 48, 64));
    rays.emplace_back(vec3(o), vec3(d));
    rays.emplace_back(vec3(o) + vec3(0.5f, 0.0f, 0.25f), glm::normalize(vec3(d)));
  }
  for (int plane = 0; plane <= 64; plane += 4) {
    for (int i = 0; i < 20; ++i) {
      const float zero = i % 2 ? 0.0f : -0.0f;
      const vec3 o(float(plane), u(rng) * 48.0f, u(rng) * 64.0f);
      rays.emplace_back(o, vec3(zero, u(rng) - 0.5f, u(rng) - 0.5f));
      rays.emplace_back(vec3(float(plane), float(plane % 48), o.z), vec3(zero, -zero, 1.0f));
    }
  }
  for (int i = 0; i < 2000; ++i) {
    const float eps = std::pow(10.0f, -2.0f - 5.0f * u(rng)) * (u(rng) < 0.5f ? -1.0f : 1.0f);
    const vec3 o(u(rng) * 64.0f, float(int(u(rng) * 12) * 4), u(rng) * 64.0f);
    rays.emplace_back(o, glm::normalize(vec3(u(rng) - 0.5f, eps, u(rng) - 0.5f)));
  }
  for (int i = 0; i < 3000; ++i) {
    vec3 o(u(rng) * 64.0f, u(rng) * 48.0f, u(rng) * 64.0f);
    const int axis = i % 3;
    o[axis] = (i / 3) % 2 ? vec3(64.0f, 48.0f, 64.0f)[axis] : 0.0f;
    if (i % 11 == 0) o[axis] += (i % 2 ? 1.0f : -1.0f) * 0.5f;
    vec3 d(dir(rng), dir(rng), dir(rng));
    if (i % 5 == 0) d[axis] = 0.0f;
    if (d != vec3(0.0f)) rays.emplace_back(o, d);
  }
  rays.emplace_back(vec3(1.5f, 20.5f, 3.0f), vec3(1.0f, 1e-25f, 0.3f));
  rays.emplace_back(vec3(3e6f, 20.5f, 3.0f), vec3(-1.0f, 0.001f, 0.3f));
  rays.emplace_back(vec3(1.5f, 20.5f, 3.0f), vec3(0.0f));
  std::shuffle(rays.begin(), rays.end(), rng);
  return rays;
}

TEST(VoxelStream, EveryKindOfRayMatchesTheReferenceWalk) {
  const VoxelWorld w = brickWorld();
  const std::vector<FloatRay> rays = everyKindOfRay();
  forEachTarget([&] { EXPECT_TRUE(sameAsReference(w, rays)); });
}

TEST(VoxelStream, EmptyOctantsMatchTheReferenceWalk) {
  const VoxelWorld w = brickWorld(true);
  const std::vector<FloatRay> rays = everyKindOfRay();
  forEachTarget([&] { EXPECT_TRUE(sameAsReference(w, rays)); });
}

TEST(VoxelStream, TerrainProbeAndCameraRaysMatchTheReferenceWalk) {
  const VoxelWorld w = buildWorld(*builtinScene("terrain"));
  std::vector<FloatRay> rays;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f), dir(-1.0f, 1.0f);
  for (int i = 0; i < 20000; ++i) {
    const vec3 d(dir(rng), dir(rng), dir(rng));
    if (glm::length(d) < 0.05f) continue;
    // Some origins are in solid voxels: those hits start solid.
    rays.emplace_back(vec3(u(rng) * 256.0f, u(rng) * 64.0f, u(rng) * 256.0f), glm::normalize(d));
    rays.emplace_back(vec3(-8.0f, 48.0f, 128.0f),
                      glm::normalize(vec3(1.0f, -0.5f * u(rng), dir(rng))));
  }
  forEachTarget([&] { EXPECT_TRUE(sameAsReference(w, rays)); });
}

TEST(VoxelStream, StreamsShorterAndLongerThanTheLanes) {
  // Lanes park when the stream runs dry; streams of 0 .. 3 vectors and a bit.
  const VoxelWorld w = brickWorld();
  const std::vector<FloatRay> all = everyKindOfRay();
  forEachTarget([&] {
    const size_t lanes = size_t(voxelStreamLanes());
    for (size_t n : {size_t(0), size_t(1), lanes - 1, lanes, lanes + 1, 2 * lanes + 3, 6 * lanes}) {
      const std::vector<FloatRay> rays(all.begin(), all.begin() + std::ptrdiff_t(n));
      EXPECT_TRUE(sameAsReference(w, rays)) << n << " rays";
    }
  });
}

TEST(VoxelStream, SparseSlotGridsMatchTheReferenceWalk) {
  // Mostly empty slots on an odd-sized grid: steps over empty 2 x 2 x 2 groups of slots,
  // groups cut by the grid's border, slot planes crossed exactly at a group's exit time.
  Scene s = test::uniformSkyScene(7, 5, 9);
  s.blocks["b"] =
      test::blockFrom([](int x, int y, int z) { return (x * 7 + y * 3 + z) % 23 == 0; });
  std::mt19937 rng(8);
  std::uniform_real_distribution<float> u(0.0f, 1.0f), dir(-1.0f, 1.0f);
  for (int i = 0; i < 12; ++i) {
    const std::array<int, 3> at{int(u(rng) * 7), int(u(rng) * 5), int(u(rng) * 9)};
    if (std::none_of(s.placements.begin(), s.placements.end(),
                     [&](const Placement& p) { return p.at == at; }))
      s.placements.push_back({at, "b", i % 24});
  }
  const VoxelWorld w = buildWorld(s);
  std::vector<FloatRay> rays;
  for (int i = 0; i < 20000; ++i) {
    vec3 d(dir(rng), dir(rng), dir(rng));
    if (glm::length(d) < 0.05f) continue;
    vec3 o(u(rng) * 112.0f, u(rng) * 80.0f, u(rng) * 144.0f);
    // Origins on slot corners with directions of equal components: planes of the slots
    // inside a group are crossed at the group's exit time.
    if (i % 4 == 0) o = glm::floor(o / 16.0f) * 16.0f, d = glm::round(d * 2.0f);
    if (i % 4 == 1) o = glm::floor(o / 32.0f) * 32.0f + vec3(0.5f, 16.0f, 0.25f);
    if (d != vec3(0.0f)) rays.emplace_back(o, d);
  }
  forEachTarget([&] { EXPECT_TRUE(sameAsReference(w, rays)); });
}

TEST(VoxelStream, WorldsWithoutBlocksOrWithoutEmptySpace) {
  for (int fill : {0, 1}) {
    Scene s = test::uniformSkyScene(2, 2, 2);
    s.blocks["b"] = test::blockFrom([&](int, int, int) { return fill; });
    if (fill) {
      for (int i = 0; i < 8; ++i) s.placements.push_back({{i & 1, i >> 1 & 1, i >> 2}, "b", 0});
    }
    const VoxelWorld w = buildWorld(s);
    std::vector<FloatRay> rays;
    std::mt19937 rng(6);
    std::uniform_real_distribution<float> pos(-4.0f, 36.0f), dir(-1.0f, 1.0f);
    for (int i = 0; i < 3000; ++i) {
      const vec3 d(dir(rng), dir(rng), dir(rng));
      if (d != vec3(0.0f)) rays.emplace_back(vec3(pos(rng), pos(rng), pos(rng)), d);
    }
    forEachTarget([&] { EXPECT_TRUE(sameAsReference(w, rays)) << "fill " << fill; });
  }
}

}  // namespace
}  // namespace rdm
