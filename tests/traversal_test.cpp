// Traversal against SPEC section 5's rules and a brute-force reference over every voxel.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "rdm/rdm_shared_cpp.h"
#include "rdm/traversal.h"
#include "test_scenes.h"

namespace rdm {
namespace {

using glm::dvec3;
using glm::ivec3;
using glm::vec3;

struct Reference {
  bool hit = false;
  ivec3 voxel{0};
  double t = 0.0;
  double gap = INFINITY;  // t distance to the runner-up voxel (ambiguity of the answer)
};

// Brute force in double: the solid voxel with the smallest entry time among those the ray
// overlaps over a positive length (edge and corner touches excluded); boundary rule for
// axes with d == 0: the cell is floor(o).
Reference bruteForce(const VoxelWorld& w, dvec3 o, dvec3 d, double min_overlap = 1e-9) {
  Reference best;
  double second = INFINITY;
  ivec3 e = w.voxelExtent();
  for (int z = 0; z < e.z; ++z)
    for (int y = 0; y < e.y; ++y)
      for (int x = 0; x < e.x; ++x) {
        if (!w.voxelAt({x, y, z})) continue;
        double t0 = 0.0, t1 = INFINITY;
        bool inside = true;
        ivec3 v(x, y, z);
        for (int a = 0; a < 3 && inside; ++a) {
          if (d[a] == 0.0) {
            inside = std::floor(o[a]) == v[a];
            continue;
          }
          double ta = (v[a] - o[a]) / d[a], tb = (v[a] + 1 - o[a]) / d[a];
          t0 = std::max(t0, std::min(ta, tb));
          t1 = std::min(t1, std::max(ta, tb));
        }
        if (!inside || !(t1 > t0 + min_overlap))
          continue;  // touches within rounding count as edges
        if (!best.hit || t0 < best.t) {
          second = best.hit ? best.t : INFINITY;
          best.hit = true, best.voxel = v, best.t = t0;
        } else {
          second = std::min(second, t0);
        }
      }
  best.gap = second - best.t;
  return best;
}

TraceHit trace(const VoxelWorld& w, vec3 o, vec3 d, float* t_out = nullptr) {
  float t = -1.0f;
  TraceHit h = traceVoxels(w, FloatRay(o, d), t);
  if (t_out) *t_out = t;
  EXPECT_FALSE(h.bound_exceeded);
  return h;
}

class TraversalTest : public ::testing::Test {
 protected:
  void SetUp() override { world_ = buildWorld(test::randomVoxelScene(3, 2, 3, 0.03, 11)); }
  void expectMatchesReference(vec3 o, vec3 d, double min_gap = 0.0) {
    Reference ref = bruteForce(world_, dvec3(o), dvec3(d));
    if (min_gap > 0.0) {
      // Float rays: skip answers that change when near-edge grazes (within min_gap) are
      // dropped, or whose runner-up is within min_gap: ambiguous at float precision.
      Reference coarse = bruteForce(world_, dvec3(o), dvec3(d), min_gap);
      if (ref.gap < min_gap || coarse.hit != ref.hit || coarse.voxel != ref.voxel) return;
    }
    float t;
    TraceHit h = trace(world_, o, d, &t);
    ASSERT_EQ(h.hit, ref.hit) << "o=" << o.x << "," << o.y << "," << o.z << " d=" << d.x << ","
                              << d.y << "," << d.z;
    if (ref.hit) {
      EXPECT_EQ(h.voxel, ref.voxel)
          << "o=" << o.x << "," << o.y << "," << o.z << " d=" << d.x << "," << d.y << "," << d.z;
      EXPECT_NEAR(t, ref.t, 1e-3 * (1.0 + ref.t));
    }
  }
  VoxelWorld world_;
};

TEST_F(TraversalTest, RandomRaysMatchBruteForce) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> pos(-4.0f, 52.0f), dir(-1.0f, 1.0f);
  for (int i = 0; i < 400; ++i) {
    vec3 d(dir(rng), dir(rng), dir(rng));
    if (glm::length(d) < 0.1f) continue;
    expectMatchesReference(vec3(pos(rng), pos(rng) * 0.6f, pos(rng)), glm::normalize(d), 1e-3);
  }
}

TEST_F(TraversalTest, IntegerOriginsAndSimultaneousCrossingsMatchExactly) {
  // Voxel-corner origins and small integer directions: diagonal rays through voxel corners
  // and edges, where several axes cross at the same t.
  std::mt19937 rng(9);
  std::uniform_int_distribution<int> pos(0, 48), comp(-2, 2);
  for (int i = 0; i < 400; ++i) {
    ivec3 d(comp(rng), comp(rng), comp(rng));
    if (d == ivec3(0)) continue;
    vec3 o(pos(rng), pos(rng) % 32, pos(rng));
    expectMatchesReference(o, vec3(d));
  }
}

TEST_F(TraversalTest, AxisParallelRaysWithSignedZeros) {
  for (float zero : {0.0f, -0.0f}) {
    for (int y = 0; y <= 32; y += 4)
      for (int z = 0; z <= 48; z += 3) {
        expectMatchesReference(vec3(-1.0f, float(y), float(z)), vec3(1.0f, zero, zero));
        expectMatchesReference(vec3(49.0f, float(y) + 0.5f, float(z)), vec3(-1.0f, zero, -zero));
        expectMatchesReference(vec3(float(z), 33.0f, float(y)), vec3(zero, -1.0f, zero));
      }
  }
}

TEST_F(TraversalTest, RaysInsideVoxelBoundaryPlanes) {
  // A ray lying in the plane y = 16 with d.y = 0 uses floor: the cells above the plane.
  for (int x = 0; x < 48; x += 5) {
    expectMatchesReference(vec3(float(x), 16.0f, -2.0f), glm::normalize(vec3(0.3f, 0.0f, 1.0f)),
                           1e-4);
    expectMatchesReference(vec3(float(x), 16.0f, -2.0f), vec3(0.0f, 0.0f, 1.0f));
  }
}

TEST_F(TraversalTest, RaysFromOutsideTheGrid) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int i = 0; i < 100; ++i) {
    vec3 target(u(rng) * 48.0f, u(rng) * 32.0f, u(rng) * 48.0f);
    vec3 origin(-20.0f + u(rng) * 90.0f, 60.0f, -20.0f + u(rng) * 90.0f);
    expectMatchesReference(origin, glm::normalize(target - origin), 1e-3);
  }
  EXPECT_FALSE(
      trace(world_, vec3(-5.0f, 5.0f, 5.0f), vec3(-1.0f, 0.0f, 0.0f)).hit);  // pointing away
  EXPECT_FALSE(trace(world_, vec3(48.0f, 5.0f, 5.0f), vec3(0.0f, 0.0f, 1.0f))
                   .hit);  // in the far boundary plane
}

TEST(Traversal, StartInSolidVoxelEndsAtZero) {
  Scene s = test::uniformSkyScene(1, 1, 1);
  s.blocks["full"].voxels.assign(4096, 1);
  s.placements.push_back({{0, 0, 0}, "full", 0});
  VoxelWorld w = buildWorld(s);
  float t = -1.0f;
  TraceHit h = traceVoxels(w, FloatRay(vec3(3.5f, 4.0f, 5.0f), vec3(0.0f, 1.0f, 0.0f)), t);
  EXPECT_TRUE(h.hit && h.started_solid);
  EXPECT_EQ(t, 0.0f);
  EXPECT_EQ(exactCentralDepth(w, ivec3(8, 8, 8), ivec3(1, 1, 1)), 0.0f);
}

TEST(Traversal, StartOnBlockBoundariesAndCorners) {
  // Two solid voxels meeting the block corner (16, 16, 16): rays leaving the corner enter
  // exactly the octant their direction signs select.
  Scene s = test::uniformSkyScene(2, 2, 2);
  s.blocks["corner_low"] =
      test::blockFrom([](int x, int y, int z) { return x == 15 && y == 15 && z == 15; });
  s.blocks["corner_high"] =
      test::blockFrom([](int x, int y, int z) { return x == 0 && y == 0 && z == 0; });
  s.placements = {{{0, 0, 0}, "corner_low", 0}, {{1, 1, 1}, "corner_high", 0}};
  VoxelWorld w = buildWorld(s);
  TraceHit up = trace(w, vec3(16.0f), glm::normalize(vec3(1.0f, 1.0f, 1.0f)));
  EXPECT_TRUE(up.started_solid);
  EXPECT_EQ(up.voxel, ivec3(16));
  TraceHit down = trace(w, vec3(16.0f), glm::normalize(vec3(-1.0f, -1.0f, -1.0f)));
  EXPECT_TRUE(down.started_solid);
  EXPECT_EQ(down.voxel, ivec3(15));
  EXPECT_FALSE(trace(w, vec3(16.0f), glm::normalize(vec3(1.0f, -1.0f, 1.0f))).hit);
  EXPECT_EQ(exactCentralDepth(w, ivec3(16), ivec3(1, -1, 1)), shared::kSkyDepth);
  EXPECT_EQ(exactCentralDepth(w, ivec3(16), ivec3(1, 1, 1)), 0.0f);
}

TEST(Traversal, DiagonalThroughCornerDoesNotEnterEdgeNeighbours) {
  Scene s = test::uniformSkyScene(1, 1, 1);
  // Solid voxels at (5,6,4) and (6,5,4) touch the diagonal path only along an edge.
  s.blocks["b"] = test::blockFrom(
      [](int x, int y, int z) { return z == 4 && ((x == 5 && y == 6) || (x == 6 && y == 5)); });
  s.placements = {{{0, 0, 0}, "b", 0}};
  VoxelWorld w = buildWorld(s);
  EXPECT_FALSE(trace(w, vec3(2.0f, 2.0f, 4.5f), glm::normalize(vec3(1.0f, 1.0f, 0.0f))).hit);
  EXPECT_EQ(exactCentralDepth(w, ivec3(2, 2, 4), ivec3(1, 1, 0)), shared::kSkyDepth);
}

TEST(Traversal, EveryLoopIsBoundedOnTheLargestGrid) {
  Scene s = test::uniformSkyScene(256, 1, 256);
  s.blocks["pillar"] = test::blockFrom([](int x, int, int z) { return x == 8 && z == 8; });
  for (int i = 0; i < 256; i += 37) s.placements.push_back({{i, 0, (i * 7) % 256}, "pillar", 0});
  VoxelWorld w = buildWorld(s);
  const int bound = 3 * 4096 + 16 + 8;
  for (int i = 0; i < 64; ++i) {
    vec3 d = glm::normalize(vec3(std::cos(i * 0.1f), 0.0001f * i, std::sin(i * 0.1f)));
    float t;
    TraceHit h = traceVoxels(w, FloatRay(vec3(2048.0f, 8.0f, 2048.0f), d), t);
    EXPECT_FALSE(h.bound_exceeded);
    EXPECT_LT(h.steps, bound);
  }
}

TEST(Traversal, ExactCentralDepthMatchesBruteForce) {
  VoxelWorld w = buildWorld(test::randomVoxelScene(3, 2, 3, 0.02, 4));
  int checked = 0;
  for (int s : {2, 4, 8})
    for (int f = 0; f < 6; ++f)
      for (int j = 0; j < s; ++j)
        for (int i = 0; i < s; ++i) {
          ivec3 slot(1, 0, 1);
          ivec3 origin = slot * 16 + ivec3(8) + 8 * shared::faceNormal(f);
          ivec3 dtbn = shared::texelCentralDirection(i, j, s);
          ivec3 dir = dtbn.x * shared::faceTangent(f) + dtbn.y * shared::faceBitangent(f) +
                      dtbn.z * shared::faceNormal(f);
          Reference ref = bruteForce(w, dvec3(origin), dvec3(dir));
          float z = exactCentralDepth(w, origin, dir);
          double expected = !ref.hit ? shared::kSkyDepth : ref.t * glm::length(dvec3(dir)) / 16.0;
          EXPECT_NEAR(z, expected, 1e-5 * expected + 1e-6)
              << "S=" << s << " f=" << f << " i=" << i << " j=" << j;
          ++checked;
        }
  EXPECT_EQ(checked, 6 * (4 + 16 + 64));
}

}  // namespace
}  // namespace rdm
