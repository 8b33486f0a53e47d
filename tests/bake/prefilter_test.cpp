// The prefiltered estimator (docs/spec.md section 3.1): its kernels, its agreement in mean with
// the naive estimator, the hard cases and determinism.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <vector>

#include "bake_identity.h"
#include "rdm/bake/bake.h"
#include "rdm/bake/prefilter.h"
#include "rdm/transport/rdm_shared_cpp.h"
#include "rdm/transport/sobol.h"
#include "test_scenes.h"

namespace rdm {
namespace {

using glm::vec3;

// Direction of texel (i, j) of mip `mip` of a map of size `base`.
vec3 tapDirection(uint32_t texel, int base) {
  int mip = 0;
  while (texel >= mipOffset(base, mip + 1)) ++mip;
  const int s = base >> mip;
  const uint32_t local = texel - mipOffset(base, mip);
  return glm::normalize(vec3(shared::texelCentralDirection(int(local) % s, int(local) / s, s)));
}

RadianceMap mapOf(int size, vec3 (*radiance)(const vec3&)) {
  RadianceMap map(size);
  for (int j = 0; j < size; ++j)
    for (int i = 0; i < size; ++i) {
      const vec3 d = glm::normalize(vec3(shared::texelCentralDirection(i, j, size)));
      map.set(i, j, radiance(d), vec3(0.0f));
    }
  map.buildMips();
  return map;
}

TEST(Prefilter, KernelsOfAConstantMapReturnTheConstant) {
  // Weights sum to 1 in float: 1e-5 relative.
  const RadianceMap map = mapOf(32, [](const vec3&) { return vec3(3.0f); });
  for (int level : {1, 2, 3, 5, 6}) {
    const int size = std::min(32, shared::hemisphereSize(level, 256));
    const PrefilterKernel& k = prefilterKernel(level, size, 32);
    ASSERT_EQ(k.begin.size(), size_t(size * size + 1));
    for (int t = 0; t < size * size; ++t) {
      vec3 mean, var;
      applyKernel(k, map, t, mean, var);
      EXPECT_NEAR(mean.x, 3.0f, 3e-5f) << "level " << level << " texel " << t;
      EXPECT_EQ(var, vec3(0.0f));
    }
  }
}

// applyKernel as it was before its 4-float loop (docs/performance.md, "Prefilter and writing
// against memcpy"): glm's vec3 sums in the taps' order.
void scalarKernel(const PrefilterKernel& kernel, const RadianceMap& map, int texel, vec3& mean,
                  vec3& variance) {
  mean = vec3(0.0f), variance = vec3(0.0f);
  for (uint32_t t = kernel.begin[size_t(texel)]; t < kernel.begin[size_t(texel) + 1]; ++t) {
    const KernelTap& tap = kernel.taps[t];
    mean += tap.weight * map.means()[tap.texel];
    variance += (tap.weight * tap.weight) * map.variances()[tap.texel];
  }
}

TEST(Prefilter, ApplyKernelGivesTheScalarSumsBitForBit) {
  // Exact: same products and sums per channel; the last texel (the 1 x 1 mip, read up to the
  // map's padding) included.
  for (int base : {16, 64}) {
    RadianceMap map(base);
    // Every mip's texels, the padding not among them.
    ASSERT_EQ(map.means().size(), size_t(mipOffset(base, int(std::bit_width(unsigned(base))))));
    uint32_t key = 1;
    for (int j = 0; j < base; ++j)
      for (int i = 0; i < base; ++i, ++key) {
        const vec3 mean(shared::randomUniform(key, 0, 0), shared::randomUniform(key, 0, 1),
                        37.0f * shared::randomUniform(key, 0, 2));
        map.set(i, j, mean, mean * mean * 1e-3f);
      }
    map.buildMips();
    const uint32_t last = uint32_t(map.means().size()) - 1;
    bool read_last = false;
    for (int level = 1; level < shared::kDiffuseLevel; ++level) {
      const int size = shared::hemisphereSize(level, base);
      const PrefilterKernel& k = prefilterKernel(level, size, base);
      for (const KernelTap& t : k.taps) read_last = read_last || t.texel == last;
      for (int t = 0; t < size * size; ++t) {
        vec3 mean, var, ref_mean, ref_var;
        applyKernel(k, map, t, mean, var);
        scalarKernel(k, map, t, ref_mean, ref_var);
        for (int c = 0; c < 3; ++c) {
          ASSERT_EQ(std::bit_cast<uint32_t>(mean[c]), std::bit_cast<uint32_t>(ref_mean[c]))
              << "base " << base << " level " << level << " texel " << t << " channel " << c;
          ASSERT_EQ(std::bit_cast<uint32_t>(var[c]), std::bit_cast<uint32_t>(ref_var[c]))
              << "base " << base << " level " << level << " texel " << t << " channel " << c;
        }
      }
    }
    EXPECT_TRUE(read_last) << "base " << base;
  }
}

TEST(Prefilter, RoughKernelsCentreOnTheirTexelsDirection) {
  // The weighted mean tap direction lies within the lobe around the texel's central direction
  // (GGX alpha 0.02 .. 0.18: within 0.25 rad); catches a wrongly mapped symmetry class.
  for (int level : {1, 2, 3}) {
    const int base = 64, size = shared::hemisphereSize(level, base);
    const PrefilterKernel& k = prefilterKernel(level, size, base);
    for (int j = 0; j < size; ++j)
      for (int i = 0; i < size; ++i) {
        const vec3 w = glm::normalize(vec3(shared::texelCentralDirection(i, j, size)));
        if (w.z < 0.5f) continue;  // near the horizon the lobe is cut off and its mean rises
        vec3 mean(0.0f);
        const int t = j * size + i;
        for (uint32_t p = k.begin[size_t(t)]; p < k.begin[size_t(t) + 1]; ++p)
          mean += k.taps[p].weight * tapDirection(k.taps[p].texel, base);
        const float angle = std::acos(std::min(1.0f, glm::dot(glm::normalize(mean), w)));
        ASSERT_LT(angle, 0.25f) << "level " << level << " texel " << i << "," << j;
      }
  }
}

BakeResult bakeWith(const Scene& s, Estimator e, int threads = 2) {
  BakeSettings settings = s.bake;
  settings.estimator = e;
  BakeOptions o;
  o.threads = threads;
  return bakeScene(buildWorld(s), settings, o);
}

// A glossy and a mirror block beside a wall, sun-lit: maps at several sizes, every level kind.
Scene glossyScene() {
  Scene s = test::uniformSkyScene(3, 2, 3);
  s.palette = {{{255, 255, 255}, 7, 0, 0},
               {{200, 200, 210}, 0, 3, 0},
               {{180, 90, 60}, 2, 1, 0},
               {{90, 180, 60}, 5, 0, 0}};
  s.blocks["wall"] = test::blockFrom([](int x, int y, int) { return x < 4 || y < 3 ? 1 : 0; });
  s.blocks["gloss"] = test::blockFrom([](int x, int, int z) { return 2 + (x + z) % 3; });
  s.placements = {{{1, 0, 1}, "wall", 0}, {{0, 0, 1}, "gloss", 0}, {{2, 0, 0}, "gloss", 7}};
  s.sun = Sun{{0.4, 1.0, 0.3}, {3.0, 3.0, 3.0}, 0.5};
  s.bake = {64, 3, 3, 16};
  return s;
}

struct RdmMean {
  double mean = 0.0, sigma = 0.0;
};

// Mean luminance over the RDM's baked faces, and its standard error: texels independent for
// the naive estimator; for the prefiltered one (texels share a map) the errors are summed, the
// fully correlated bound.
RdmMean rdmMean(const RdmData& d, bool correlated) {
  double sum = 0.0, err = 0.0;
  size_t n = 0;
  const int S = d.id.size;
  for (int y = 0; y < d.image.height; ++y)
    for (int x = 0; x < d.image.width; ++x) {
      if (d.skipped[size_t((y / S) * 2 + x / S)]) continue;
      const size_t p = (size_t(y) * d.image.width + x) * 3;
      sum += luminance(vec3(d.image.at(x, y, 0), d.image.at(x, y, 1), d.image.at(x, y, 2)));
      const double e = luminance(vec3(d.stderr_rgb[p], d.stderr_rgb[p + 1], d.stderr_rgb[p + 2]));
      err += correlated ? e : e * e;
      ++n;
    }
  if (n == 0) return {};
  return {sum / double(n), correlated ? err / double(n) : std::sqrt(err) / double(n)};
}

// Every RDM's mean agrees within the combined standard error, z = |difference| / (sigma plus 1 %
// of the mean; the 1 % allows the prefilter's own deterministic bias: the map texel's footprint
// and the kernels' quadrature, docs/spec.md 3.1). The standard errors come from the samples
// themselves and run low where the light is heavy-tailed (sun-lit bounces at 32 spp), so the
// test allows 2 % of RDMs (at least one) past z = 4 and none past z = 8.
void expectMeansAgree(const Scene& s) {
  BakeResult naive = bakeWith(s, Estimator::kNaive);
  BakeResult pre = bakeWith(s, Estimator::kPrefiltered);
  ASSERT_EQ(naive.rdms.size(), pre.rdms.size());
  double worst = 0.0;
  size_t past4 = 0;
  for (size_t i = 0; i < naive.rdms.size(); ++i) {
    ASSERT_TRUE(naive.rdms[i].id == pre.rdms[i].id);
    const RdmMean a = rdmMean(naive.rdms[i], false), b = rdmMean(pre.rdms[i], true);
    const double unit = std::hypot(a.sigma, b.sigma) + 0.01 * std::abs(a.mean) + 1e-6;
    const double z = std::abs(a.mean - b.mean) / unit;
    worst = std::max(worst, z);
    past4 += z > 4.0 ? 1 : 0;
    EXPECT_LE(z, 8.0) << "RDM " << i << " level " << naive.rdms[i].id.level << ": naive " << a.mean
                      << " +- " << a.sigma << ", prefiltered " << b.mean << " +- " << b.sigma;
  }
  EXPECT_LE(past4, std::max<size_t>(1, naive.rdms.size() / 50));
  std::printf("[ means ] %zu RDMs: worst z %.2f, %zu past z = 4\n", naive.rdms.size(), worst,
              past4);
}

TEST(Prefilter, RdmMeansAgreeWithTheNaiveEstimatorOnAGlossySunLitScene) {
  expectMeansAgree(glossyScene());
}

TEST(Prefilter, RdmMeansAgreeWithTheNaiveEstimatorOnChessAndIsland) {
  for (const char* name : {"chess", "island"}) {
    auto scene = loadSceneByNameOrPath(name);
    ASSERT_TRUE(scene.ok()) << scene.error();
    scene->bake.spp = 32;
    scene->bake.max_hemisphere = 16;
    scene->bake.max_bounces = 3;
    SCOPED_TRACE(name);
    expectMeansAgree(*scene);
  }
}

// A lone block of r = 1 and r = 3 voxels under a unit sky.
Scene roughFurnace() {
  Scene s = test::uniformSkyScene(3, 3, 3, 1.0);
  s.palette = {{{255, 255, 255}, 3, 0, 0}, {{255, 255, 255}, 1, 0, 0}};
  s.blocks["b"] = test::blockFrom([](int x, int, int) { return 1 + x % 2; });
  s.placements = {{{1, 1, 1}, "b", 0}};
  s.bake.max_hemisphere = 16;
  return s;
}

TEST(Prefilter, WhiteFurnaceOfRoughBlocksStaysAtOne) {
  // Every face sees only sky, so every level's texel is 1 to float rounding of the kernel
  // weights (1e-5).
  const Scene s = roughFurnace();
  BakeResult r = bakeWith(s, Estimator::kPrefiltered);
  ASSERT_EQ(r.rdms.size(), 3u);
  for (const RdmData& d : r.rdms)
    for (int y = 0; y < d.image.height; ++y)
      for (int x = 0; x < d.image.width; ++x)
        for (int c = 0; c < 3; ++c) ASSERT_NEAR(d.image.at(x, y, c), 1.0f, 1e-5f);
}

// Rough faces inside an opaque shell under a bright sun: nothing reaches them.
Scene darkBox() {
  Scene s = test::uniformSkyScene(3, 3, 3, 5.0);
  s.palette = {{{255, 255, 255}, 7, 0, 0}, {{255, 255, 255}, 2, 1, 0}};
  s.sun = Sun{{0.3, 1.0, 0.2}, {1e5, 1e5, 1e5}, 0.27};
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) {
        const bool centre = i == 1 && j == 1 && k == 1;
        const std::string name = centre ? "glossy" : "wall";
        if (!s.blocks.count(name)) {
          s.blocks[name] = centre ? test::blockFrom([](int x, int y, int z) {
            return x > 5 && x < 10 && y > 5 && y < 10 && z > 5 && z < 10 ? 2 : 0;
          })
                                  : test::blockFrom([](int, int, int) { return 1; });
        }
        s.placements.push_back({{i, j, k}, name, 0});
      }
  s.bake.max_hemisphere = 16;
  return s;
}

TEST(Prefilter, ClosedDarkBoxIsExactlyZero) {
  const Scene s = darkBox();
  BakeResult r = bakeWith(s, Estimator::kPrefiltered);
  bool any_glossy = false;
  for (const RdmData& d : r.rdms) {
    if (d.id.slot != glm::ivec3(1, 1, 1)) continue;
    any_glossy = any_glossy || d.id.level == 2;
    for (int y = 0; y < d.image.height; ++y)
      for (int x = 0; x < d.image.width; ++x)
        for (int c = 0; c < 3; ++c) ASSERT_EQ(d.image.at(x, y, c), 0.0f);
  }
  EXPECT_TRUE(any_glossy);
}

// Mirrors lit by a 1e4 sun and emitters at 1e4.
Scene brightSources() {
  Scene s = test::uniformSkyScene(2, 2, 2, 1.0);
  s.palette = {{{255, 255, 255}, 0, 3, 3}, {{255, 255, 255}, 7, 0, 3}, {{200, 200, 200}, 1, 3, 0}};
  s.emission_scale = 1e4;
  s.sun = Sun{{0.2, 1.0, 0.1}, {1e4, 1e4, 1e4}, 0.01};
  s.blocks["lamp"] = test::blockFrom(
      [](int x, int y, int z) { return (x + y + z) % 5 == 0 ? 2 : ((x * y) % 7 == 0 ? 1 : 0); });
  s.blocks["mirror"] = test::blockFrom([](int x, int, int) { return x < 8 ? 3 : 0; });
  s.placements = {{{0, 0, 0}, "lamp", 0}, {{1, 0, 0}, "mirror", 3}, {{0, 1, 1}, "mirror", 9}};
  s.bake = {4, 8, 1, 16};
  return s;
}

TEST(Prefilter, SunLitMirrorsAndBrightEmittersStayFiniteAndBounded) {
  const Scene s = brightSources();
  BakeResult r = bakeWith(s, Estimator::kPrefiltered);
  // Bound: the brightest source (an emitter, the sun's disc seen in a mirror, the sky) times
  // the albedo bound 1.017 per bounce (docs/spec.md section 5).
  const VoxelWorld w = buildWorld(s);
  float brightest =
      std::max(1.0f, std::max(w.sun.radiance.x, std::max(w.sun.radiance.y, w.sun.radiance.z)));
  for (const Material& m : w.materials)
    brightest = std::max(brightest, std::max(m.emission.x, std::max(m.emission.y, m.emission.z)));
  const float bound = brightest * std::pow(1.017f, float(s.bake.max_bounces));
  for (const RdmData& d : r.rdms) {
    for (int y = 0; y < d.image.height; ++y)
      for (int x = 0; x < d.image.width; ++x)
        for (int c = 0; c < 3; ++c) {
          const float v = d.image.at(x, y, c);
          ASSERT_TRUE(std::isfinite(v) && v >= 0.0f && v <= bound) << v << " > " << bound;
        }
    for (float e : d.stderr_rgb) ASSERT_TRUE(std::isfinite(e) && e >= 0.0f);
  }
}

using test::bitIdentical;

TEST(Prefilter, RdmMeansAgreeWithTheNaiveEstimatorOnTheHardCases) {
  for (Scene s : {roughFurnace(), darkBox(), brightSources()}) {
    s.bake.spp = 64;
    expectMeansAgree(s);
  }
}

TEST(Prefilter, BitIdenticalAcrossThreadsShardsAndUnitOrder) {
  const Scene s = glossyScene();
  const BakeResult one = bakeWith(s, Estimator::kPrefiltered, 1);
  EXPECT_TRUE(bitIdentical(one, bakeWith(s, Estimator::kPrefiltered, 2)));
  // Units run in reverse order: each map is traced by a different unit than before.
  const VoxelWorld world = buildWorld(s);
  BakeSession session(world, s.bake, listRdms(world, s.bake), BakeOptions{});
  for (size_t i = session.units().size(); i-- > 0;) (void)session.runUnit(i);
  EXPECT_TRUE(bitIdentical(one, session.finish(0.0, 0, false)));
  // Shards: every RDM of shard k equals the full bake's.
  for (int k = 0; k < 3; ++k) {
    BakeOptions o;
    o.shard_index = k, o.shard_count = 3;
    BakeResult shard = bakeScene(world, s.bake, o);
    for (const RdmData& d : shard.rdms) {
      auto it = std::find_if(one.rdms.begin(), one.rdms.end(),
                             [&](const RdmData& x) { return x.id == d.id; });
      ASSERT_NE(it, one.rdms.end());
      EXPECT_EQ(it->image.pixels, d.image.pixels);
    }
  }
}

}  // namespace
}  // namespace rdm

namespace rdm {
namespace {

TEST(Sobol, FirstPowerOfTwoPointsStratifyEveryElementaryInterval) {
  // For N = 2^m points and every split a + b = m, each of the 2^a x 2^b boxes holds exactly
  // one point: the (0, m, 2)-net property the nested scramble must keep, for every key.
  for (uint32_t seed : {0u, 1u, 0xdeadbeefu, 12345u}) {
    for (int m = 1; m <= 8; ++m) {
      const uint32_t n = 1u << m;
      for (int a = 0; a <= m; ++a) {
        std::vector<int> count(n, 0);
        for (uint32_t i = 0; i < n; ++i) {
          const Point2 p = owenSobol2(i, seed);
          ASSERT_TRUE(p.u0 >= 0.0f && p.u0 < 1.0f && p.u1 >= 0.0f && p.u1 < 1.0f);
          const uint32_t x = uint32_t(p.u0 * float(1u << a)),
                         y = uint32_t(p.u1 * float(1u << (m - a)));
          ++count[(y << a) | x];
        }
        for (int c : count) ASSERT_EQ(c, 1) << "seed " << seed << " m " << m << " a " << a;
      }
    }
  }
}

TEST(Sobol, KeysGiveDifferentPoints) {
  int same = 0;
  for (uint32_t i = 0; i < 64; ++i) same += owenSobol2(i, 1).u0 == owenSobol2(i, 2).u0 ? 1 : 0;
  EXPECT_LT(same, 4);
}

}  // namespace
}  // namespace rdm
