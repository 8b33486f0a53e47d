// Traversal against docs/spec.md section 5's rules and a brute-force reference over every voxel.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

#include "rdm/trace/shared_walk.h"
#include "rdm/trace/traversal.h"
#include "rdm/transport/rdm_shared_cpp.h"
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

// --- The accelerated walk against referenceWalk, bit for bit (docs/performance.md) ---

// Slots in visit order with consecutive repeats dropped (how every visitor reads them).
struct SlotTrail {
  std::vector<int>* slots;
  void operator()(int slot) const {
    if (slots->empty() || slots->back() != slot) slots->push_back(slot);
  }
};

// walkStartInside, the viewer's start for origins in the grid, gives walkStart's state.
bool sameStartInside(const VoxelWorld& world, const FloatRay& ray) {
  const ivec3 extent = world.voxelExtent();
  shared::ShWalk w, inside;
  if (!shared::walkStart(w, ray.o, ray.d, extent)) return true;
  if (!glm::all(glm::greaterThanEqual(ray.o, vec3(0.0f))) ||
      !glm::all(glm::lessThan(ray.o, vec3(extent))))
    return true;
  shared::walkStartInside(inside, ray.o, ray.d);
  return inside.cell == w.cell && inside.mask == w.mask && inside.t == w.t;
}

template <class Ray>
::testing::AssertionResult sameWalk(const VoxelWorld& w, const Ray& ray) {
  typename Ray::Time t_fast{}, t_ref{};
  std::vector<int> fast_slots, ref_slots;
  TraceHit fast = traceVoxels(w, ray, t_fast, SlotTrail{&fast_slots});
  TraceHit ref = detail::referenceWalk(w, ray, t_ref, SlotTrail{&ref_slots});
  // Without a visitor the walk may also step over empty groups of slots.
  typename Ray::Time t_plain{};
  TraceHit plain = traceVoxels(w, ray, t_plain);
  auto sameTime = [&](const typename Ray::Time& t) {
    if constexpr (std::is_same_v<Ray, FloatRay>) {
      return !ref.hit || std::memcmp(&t, &t_ref, sizeof(float)) == 0;
    } else {
      return !ref.hit || (t.num == t_ref.num && t.den == t_ref.den);
    }
  };
  auto sameHit = [&](const TraceHit& h) {
    return h.hit == ref.hit && h.voxel == ref.voxel && h.axis == ref.axis &&
           h.palette == ref.palette && h.started_solid == ref.started_solid;
  };
  bool same_t = sameTime(t_fast) && sameTime(t_plain);
  bool same_shared = true;
  if constexpr (std::is_same_v<Ray, FloatRay>) {
    float t_shared = 0.0f;
    same_shared = sameHit(traceSharedWalk(w, ray, t_shared)) && sameStartInside(w, ray);
    same_t = same_t && sameTime(t_shared);
  }
  if (sameHit(fast) && sameHit(plain) && same_shared && same_t && fast_slots == ref_slots)
    return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << "o=" << ray.o.x << "," << ray.o.y << "," << ray.o.z << " d=" << ray.d.x << ","
         << ray.d.y << "," << ray.d.z << " hit " << fast.hit << "/" << ref.hit << " voxel "
         << fast.voxel.x << "," << fast.voxel.y << "," << fast.voxel.z << "/" << ref.voxel.x << ","
         << ref.voxel.y << "," << ref.voxel.z << " axis " << fast.axis << "/" << ref.axis
         << " without visitor " << plain.hit << " " << plain.voxel.x << "," << plain.voxel.y << ","
         << plain.voxel.z << " axis " << plain.axis << " shared walk " << same_shared << " same t "
         << same_t << " slots " << fast_slots.size() << "/" << ref_slots.size();
}

// Blocks of whole 4^3 bricks: empty, full, or sparse, so brick skips meet every neighbour.
Scene brickScene(int sx, int sy, int sz, uint32_t seed) {
  Scene s = test::uniformSkyScene(sx, sy, sz);
  s.palette.push_back({{200, 40, 40}, 3, 0, 0});
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int k = 0; k < sz; ++k)
    for (int j = 0; j < sy; ++j)
      for (int i = 0; i < sx; ++i) {
        if (u(rng) < 0.25) continue;
        std::array<int, 64> kind;
        for (int& b : kind) b = u(rng) < 0.55 ? 0 : (u(rng) < 0.3 ? 1 : 2);
        std::string name =
            "k" + std::to_string(i) + "_" + std::to_string(j) + "_" + std::to_string(k);
        s.blocks[name] = test::blockFrom([&](int x, int y, int z) {
          int b = kind[x / 4 + 4 * (y / 4) + 16 * (z / 4)];
          return b == 1 ? 1 + (x + y + z) % 2 : (b == 2 && u(rng) < 0.08 ? 2 : 0);
        });
        s.placements.push_back({{i, j, k}, name, int(u(rng) * 24) % 24});
      }
  return s;
}

class FastWalkTest : public ::testing::Test {
 protected:
  void SetUp() override { world_ = buildWorld(brickScene(4, 3, 4, 21)); }
  VoxelWorld world_;  // 64 x 48 x 64 voxels
};

TEST_F(FastWalkTest, RandomRaysAreBitIdentical) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> pos(-8.0f, 72.0f), dir(-1.0f, 1.0f);
  for (int i = 0; i < 20000; ++i) {
    vec3 d(dir(rng), dir(rng), dir(rng));
    if (glm::length(d) < 0.05f) continue;
    ASSERT_TRUE(
        sameWalk(world_, FloatRay(vec3(pos(rng), pos(rng) * 0.7f, pos(rng)), glm::normalize(d))));
  }
}

TEST_F(FastWalkTest, IntegerOriginsThroughEdgesAndCornersAreBitIdentical) {
  // Origins on voxel, brick and slot corners; directions with equal components, so
  // several axes cross at one t, on brick and slot planes too.
  std::mt19937 rng(2);
  std::uniform_int_distribution<int> pos(0, 16), comp(-3, 3);
  for (int i = 0; i < 20000; ++i) {
    ivec3 d(comp(rng), comp(rng), comp(rng));
    if (d == ivec3(0)) continue;
    const int scale = i % 3 == 0 ? 4 : (i % 3 == 1 ? 1 : 16);
    ivec3 o = ivec3(pos(rng), pos(rng), pos(rng)) * scale;
    o = glm::min(o, ivec3(64, 48, 64));
    ASSERT_TRUE(sameWalk(world_, FloatRay(vec3(o), vec3(d))));
    ASSERT_TRUE(
        sameWalk(world_, FloatRay(vec3(o) + vec3(0.5f, 0.0f, 0.25f), glm::normalize(vec3(d)))));
    ASSERT_TRUE(sameWalk(world_, ExactRay(o, d)));
  }
}

TEST_F(FastWalkTest, RaysInBrickAndSlotPlanesAreBitIdentical) {
  // A ray lying in a brick or slot plane (d = +-0 on that axis), and rays along brick and
  // slot edges.
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int plane = 0; plane <= 64; plane += 4)
    for (int i = 0; i < 40; ++i) {
      float zero = i % 2 ? 0.0f : -0.0f;
      vec3 o(float(plane), u(rng) * 48.0f, u(rng) * 64.0f);
      vec3 d(zero, u(rng) - 0.5f, u(rng) - 0.5f);
      ASSERT_TRUE(sameWalk(world_, FloatRay(o, d)));
      ASSERT_TRUE(
          sameWalk(world_, FloatRay(vec3(o.y, float(plane % 48), o.z), vec3(d.y, zero, d.z))));
      ASSERT_TRUE(sameWalk(
          world_, FloatRay(vec3(float(plane), float(plane % 48), o.z), vec3(zero, -zero, 1.0f))));
      ASSERT_TRUE(sameWalk(
          world_, FloatRay(vec3(float(plane), float(plane % 48), -3.0f), vec3(0.0f, 0.0f, 1.0f))));
    }
}

TEST_F(FastWalkTest, GrazingRaysAreBitIdentical) {
  // Slopes of 1e-7 .. 1e-2 keep a ray next to a plane for many bricks; 1e-25 falls to the
  // reference walk (irregular), as do huge origins.
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int i = 0; i < 4000; ++i) {
    float eps = std::pow(10.0f, -2.0f - 5.0f * u(rng)) * (u(rng) < 0.5f ? -1.0f : 1.0f);
    vec3 o(u(rng) * 64.0f, float(int(u(rng) * 12) * 4), u(rng) * 64.0f);
    vec3 d = glm::normalize(vec3(u(rng) - 0.5f, eps, u(rng) - 0.5f));
    ASSERT_TRUE(sameWalk(world_, FloatRay(o, d)));
    ASSERT_TRUE(sameWalk(world_, FloatRay(o + vec3(0.0f, 1e-6f, 0.0f), d)));
  }
  EXPECT_TRUE(sameWalk(world_, FloatRay(vec3(1.5f, 20.5f, 3.0f), vec3(1.0f, 1e-25f, 0.3f))));
  EXPECT_TRUE(sameWalk(world_, FloatRay(vec3(3e6f, 20.5f, 3.0f), vec3(-1.0f, 0.001f, 0.3f))));
  EXPECT_FALSE(FloatRay(vec3(1.5f), vec3(1.0f, 1e-25f, 0.3f)).regular());
}

TEST_F(FastWalkTest, GridBorderRaysAreBitIdentical) {
  // Origins on and just outside the grid's faces, edges and corners, inward, outward and
  // along the face.
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.0f, 1.0f), dir(-1.0f, 1.0f);
  const vec3 e(64.0f, 48.0f, 64.0f);
  for (int i = 0; i < 6000; ++i) {
    vec3 o(u(rng) * e.x, u(rng) * e.y, u(rng) * e.z);
    int axis = i % 3;
    o[axis] = (i / 3) % 2 ? e[axis] : 0.0f;
    if (i % 7 == 0) o[(axis + 1) % 3] = 0.0f;
    if (i % 11 == 0) o[axis] += (i % 2 ? 1.0f : -1.0f) * 0.5f;
    vec3 d(dir(rng), dir(rng), dir(rng));
    if (i % 5 == 0) d[axis] = 0.0f;
    if (d == vec3(0.0f)) continue;
    ASSERT_TRUE(sameWalk(world_, FloatRay(o, d)));
    ASSERT_TRUE(sameWalk(world_, ExactRay(ivec3(glm::round(o)), ivec3(glm::round(d * 3.0f)) +
                                                                    ivec3(0, 0, d == vec3(0.0f)))));
  }
}

TEST(FastWalk, SparseSlotGridsAreBitIdentical) {
  // Mostly empty slots on an odd-sized grid: steps over empty 2 x 2 x 2 groups of slots,
  // groups cut by the grid's border, and slot skips between them.
  Scene s = test::uniformSkyScene(7, 5, 9);
  s.blocks["b"] =
      test::blockFrom([](int x, int y, int z) { return (x * 7 + y * 3 + z) % 23 == 0; });
  std::mt19937 rng(8);
  std::uniform_real_distribution<float> u(0.0f, 1.0f), dir(-1.0f, 1.0f);
  for (int i = 0; i < 12; ++i)
    s.placements.push_back({{int(u(rng) * 7), int(u(rng) * 5), int(u(rng) * 9)}, "b", i % 24});
  std::sort(s.placements.begin(), s.placements.end(),
            [](const Placement& a, const Placement& b) { return a.at < b.at; });
  s.placements.erase(
      std::unique(s.placements.begin(), s.placements.end(),
                  [](const Placement& a, const Placement& b) { return a.at == b.at; }),
      s.placements.end());
  VoxelWorld w = buildWorld(s);
  for (int i = 0; i < 20000; ++i) {
    vec3 d(dir(rng), dir(rng), dir(rng));
    if (glm::length(d) < 0.05f) continue;
    vec3 o(u(rng) * 112.0f, u(rng) * 80.0f, u(rng) * 144.0f);
    if (i % 4 == 0) o = glm::floor(o / 16.0f) * 16.0f, d = glm::round(d * 2.0f);
    if (d == vec3(0.0f)) continue;
    ASSERT_TRUE(sameWalk(w, FloatRay(o, d)));
  }
}

TEST(FastWalk, EmptyAndFullWorldsAreBitIdentical) {
  for (int fill : {0, 1}) {
    Scene s = test::uniformSkyScene(2, 2, 2);
    s.blocks["b"] = test::blockFrom([&](int, int, int) { return fill; });
    if (fill) s.placements = {{{0, 0, 0}, "b", 0}, {{1, 1, 1}, "b", 0}, {{1, 0, 1}, "b", 0}};
    VoxelWorld w = buildWorld(s);
    std::mt19937 rng(6);
    std::uniform_real_distribution<float> pos(-4.0f, 36.0f), dir(-1.0f, 1.0f);
    for (int i = 0; i < 3000; ++i) {
      vec3 d(dir(rng), dir(rng), dir(rng));
      if (d == vec3(0.0f)) continue;
      ASSERT_TRUE(sameWalk(w, FloatRay(vec3(pos(rng), pos(rng), pos(rng)), d)));
    }
  }
}

TEST(FastWalk, TerrainProbeAndCameraRaysAreBitIdentical) {
  VoxelWorld w = buildWorld(*builtinScene("terrain"));
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f), dir(-1.0f, 1.0f);
  for (int i = 0; i < 20000; ++i) {
    vec3 d(dir(rng), dir(rng), dir(rng));
    if (glm::length(d) < 0.05f) continue;
    vec3 o(u(rng) * 256.0f, u(rng) * 64.0f, u(rng) * 256.0f);
    ASSERT_TRUE(sameWalk(w, FloatRay(o, glm::normalize(d))));
    vec3 cam(-8.0f, 48.0f, 128.0f);
    ASSERT_TRUE(sameWalk(w, FloatRay(cam, glm::normalize(vec3(1.0f, -0.5f * u(rng), dir(rng))))));
  }
}

}  // namespace
}  // namespace rdm
