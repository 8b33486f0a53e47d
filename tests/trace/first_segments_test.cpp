// Paths whose first segment comes from a stream batch (rdm/trace/first_segments.h) against paths
// that trace it themselves: the same radiance, bit for bit.
#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <vector>

#include "rdm/scene/scene.h"
#include "rdm/trace/integrator.h"

namespace rdm {
namespace {

using glm::vec3;

bool sameBits(const vec3& a, const vec3& b) {
  return std::memcmp(&a, &b, sizeof(vec3)) == 0;
}

TEST(FirstSegments, PathsFromABatchEqualPathsTracedWhole) {
  Scene scene = *builtinScene("terrain");
  scene.sun = Sun{{0.4, 1.0, 0.3}, {3.0, 3.0, 3.0}, 0.5};
  const VoxelWorld world = buildWorld(scene);
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> u(0.0f, 1.0f), dir(-1.0f, 1.0f);
  struct Path {
    vec3 o, d;
    uint32_t key;
  };
  std::vector<Path> paths;
  FirstSegments first;
  for (uint32_t i = 0; i < 4000; ++i) {
    vec3 d(dir(rng), dir(rng), dir(rng));
    if (glm::length(d) < 0.05f) continue;
    const vec3 o = i % 2 ? vec3(-8.0f, 48.0f, 128.0f)
                         : vec3(u(rng) * 256.0f, 30.0f + u(rng) * 34.0f, u(rng) * 256.0f);
    paths.push_back({o, glm::normalize(d), i});
    first.add(o, paths.back().d);
  }
  first.trace(world);
  PathStats batch_stats, whole_stats;
  size_t taken = 0;
  for (const Path& p : paths) {
    const FirstSegment* seg = first.take(p.o, p.d);
    taken += seg != nullptr;
    const vec3 from_batch = tracePath<true, false>(world, 3, p.o, p.d, p.key, PathOrigin::kCamera,
                                                   batch_stats, NoRecorder(), seg);
    const vec3 whole =
        tracePath<true, false>(world, 3, p.o, p.d, p.key, PathOrigin::kCamera, whole_stats);
    ASSERT_TRUE(sameBits(from_batch, whole)) << "path " << p.key;
  }
  EXPECT_EQ(taken, paths.size());
  EXPECT_EQ(batch_stats.rays, whole_stats.rays);
}

TEST(FirstSegments, ARayOutOfOrderIsNotTaken) {
  const VoxelWorld world = buildWorld(*builtinScene("terrain"));
  FirstSegments first;
  first.add(vec3(10.5f, 40.0f, 10.5f), vec3(0.0f, -1.0f, 0.0f));
  first.add(vec3(20.5f, 40.0f, 20.5f), vec3(0.0f, -1.0f, 0.0f));
  first.trace(world);
  EXPECT_EQ(first.take(vec3(20.5f, 40.0f, 20.5f), vec3(0.0f, -1.0f, 0.0f)), nullptr);
  EXPECT_EQ(first.take(vec3(10.5f, 40.0f, 10.5f), vec3(-0.0f, -1.0f, 0.0f)), nullptr);
  const FirstSegment* a = first.take(vec3(10.5f, 40.0f, 10.5f), vec3(0.0f, -1.0f, 0.0f));
  ASSERT_NE(a, nullptr);
  EXPECT_TRUE(a->hit.hit);
  EXPECT_NE(first.take(vec3(20.5f, 40.0f, 20.5f), vec3(0.0f, -1.0f, 0.0f)), nullptr);
  EXPECT_EQ(first.take(vec3(20.5f, 40.0f, 20.5f), vec3(0.0f, -1.0f, 0.0f)), nullptr);
}

}  // namespace
}  // namespace rdm
