// The RDM bake: white furnace, bounds, zero and extreme cases, determinism, rotations.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "bake_identity.h"
#include "rdm/bake/bake.h"
#include "rdm/trace/integrator.h"
#include "rdm/transport/rdm_shared_cpp.h"
#include "test_scenes.h"

namespace rdm {
namespace {

using glm::ivec3;
using glm::vec3;

BakeResult bake(const Scene& s, int threads = 2, bool all_effects = false) {
  BakeOptions o;
  o.threads = threads;
  o.all_effects = all_effects;
  return bakeScene(buildWorld(s), s.bake, o);
}

vec3 texel(const RdmData& d, int x, int y) {
  return {d.image.at(x, y, 0), d.image.at(x, y, 1), d.image.at(x, y, 2)};
}
vec3 sigma(const RdmData& d, int x, int y) {
  size_t p = (size_t(y) * d.image.width + x) * 3;
  return {d.stderr_rgb[p], d.stderr_rgb[p + 1], d.stderr_rgb[p + 2]};
}

using test::bitIdentical;

using test::mixedScene;

TEST(Bake, WhiteFurnaceFacesSeeingOnlySkyEqualIt) {
  Scene s = test::uniformSkyScene(3, 3, 3, 1.0);
  s.blocks["white"].voxels.assign(4096, 1);
  s.placements = {{{1, 1, 1}, "white", 0}};
  BakeResult r = bake(s);
  ASSERT_EQ(r.rdms.size(), 1u);
  for (float v : r.rdms[0].image.pixels) {
    if (v != shared::kSkyDepth) {
      EXPECT_EQ(v, 1.0f);  // radiance exactly the sky's
    }
  }
  EXPECT_EQ(r.report.faces_skipped, 0);
}

TEST(Bake, WhiteFurnaceFacesSeeingWallsStayWithinAlbedoBound) {
  // An L of white r = 7 blocks under a uniform unit sky: radiance seen is at most
  // a_max^bounces (a_max = 1.017, docs/spec.md section 5), at least the sky-only part's share.
  Scene s = test::uniformSkyScene(3, 3, 3, 1.0);
  s.blocks["white"].voxels.assign(4096, 1);
  s.placements = {{{0, 0, 0}, "white", 0},
                  {{1, 0, 0}, "white", 0},
                  {{1, 1, 0}, "white", 0},
                  {{1, 0, 1}, "white", 0}};
  s.bake = {64, 4, 1, 8};
  BakeResult r = bake(s);
  const double bound = std::pow(1.017, s.bake.max_bounces);
  for (const RdmData& d : r.rdms) {
    for (int y = 0; y < d.image.height; ++y)
      for (int x = 0; x < d.image.width; ++x) {
        if (d.skipped[(y / d.id.size) * 2 + x / d.id.size]) continue;
        vec3 l = texel(d, x, y), e = sigma(d, x, y);
        EXPECT_LE(l.x, bound + 4.0 * e.x + 1e-6);
        EXPECT_GE(l.x,
                  0.9 - 4.0 * e.x);  // walls are at least 0.97-white; losses only past 4 bounces
      }
  }
}

TEST(Transport, DiffuseWhiteFloorReturnsSkyTimesAlbedoWithinRouletteNoise) {
  // Camera rays straight down at a white r = 7 floor under a unit sky, 64 bounces with
  // Russian roulette: the mean is the normal-view albedo 0.972 (docs/spec.md section 5).
  Scene s = test::uniformSkyScene(1, 1, 1, 1.0);
  s.blocks["floor"] = test::blockFrom([](int, int y, int) { return y < 2 ? 1 : 0; });
  s.placements = {{{0, 0, 0}, "floor", 0}};
  VoxelWorld w = buildWorld(s);
  PathStats stats;
  double sum = 0.0, sum2 = 0.0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    uint32_t key = shared::pathKey(1, 0, 0, uint32_t(i), 0);
    vec3 o(8.0f, 15.0f, 8.0f);
    float l =
        tracePath<false, false>(w, 64, o, vec3(0.0f, -1.0f, 0.0f), key, PathOrigin::kCamera, stats)
            .x;
    sum += l, sum2 += double(l) * l;
  }
  double mean = sum / n, err = std::sqrt((sum2 / n - mean * mean) / n);
  EXPECT_NEAR(mean, 0.972, 4.0 * err + 0.002);
}

TEST(Transport, ClosedDarkBoxGivesExactlyZero) {
  Scene s = test::uniformSkyScene(1, 1, 1, 5.0);
  s.blocks["box"] = test::blockFrom([](int x, int y, int z) {
    return x < 2 || y < 2 || z < 2 || x > 13 || y > 13 || z > 13 ? 1 : 0;
  });
  s.placements = {{{0, 0, 0}, "box", 0}};
  s.sun = Sun{{0.3, 1.0, 0.2}, {1e5, 1e5, 1e5}, 0.27};
  VoxelWorld w = buildWorld(s);
  PathStats stats;
  for (int i = 0; i < 2000; ++i) {
    vec3 d =
        glm::normalize(vec3(std::sin(i * 1.3f), std::cos(i * 0.7f), std::sin(i * 0.31f + 1.0f)));
    vec3 l = tracePath<true, true>(w, 64, vec3(8.0f, 8.0f, 8.0f), d, shared::pathKey(1, 0, 0, i, 0),
                                   PathOrigin::kCamera, stats);
    ASSERT_EQ(l, vec3(0.0f));
  }
}

TEST(Bake, ExtremeEmissionAndSunStayFinite) {
  Scene s = test::uniformSkyScene(2, 2, 2, 1e5);
  s.palette = {{{255, 255, 255}, 0, 3, 3}, {{255, 255, 255}, 7, 0, 3}, {{10, 10, 10}, 1, 0, 0}};
  s.emission_scale = 1e5;
  s.sun = Sun{{0.2, 1.0, 0.1}, {1e5, 1e5, 1e5}, 0.01};
  s.blocks["lamp"] = test::blockFrom(
      [](int x, int y, int z) { return (x + y + z) % 5 == 0 ? 2 : ((x * y) % 7 == 0 ? 1 : 0); });
  s.blocks["glossy"] = test::blockFrom([](int x, int, int) { return x < 8 ? 3 : 0; });
  s.placements = {{{0, 0, 0}, "lamp", 0}, {{1, 0, 0}, "glossy", 3}, {{0, 1, 1}, "glossy", 9}};
  s.bake = {4, 8, 1, 8};
  BakeResult r = bake(s);
  for (const RdmData& d : r.rdms)
    for (float v : d.image.pixels) ASSERT_TRUE(std::isfinite(v));
  EXPECT_TRUE(r.report.effects.sun && r.report.effects.emitters);
}

TEST(Bake, BitIdenticalAcrossThreadCounts) {
  Scene s = mixedScene();
  s.sun = Sun{{0.4, 1.0, 0.3}, {3.0, 3.0, 3.0}, 0.5};
  EXPECT_TRUE(bitIdentical(bake(s, 1), bake(s, 2)));
}

TEST(Bake, BitIdenticalWithAbsentEffectsCompiledIn) {
  Scene s = mixedScene();  // no sun, no emitters
  BakeResult specialised = bake(s, 2, false), general = bake(s, 2, true);
  EXPECT_FALSE(specialised.report.effects.sun || specialised.report.effects.emitters);
  EXPECT_TRUE(bitIdentical(specialised, general));
  s.sun = Sun{{0.4, 1.0, 0.3}, {3.0, 3.0, 3.0}, 0.5};  // sun present, emitters absent
  EXPECT_TRUE(bitIdentical(bake(s, 2, false), bake(s, 2, true)));
}

TEST(Bake, StreamedFirstSegmentsChangeNoBit) {
  // A bake without slot recording traces the first segments of each texel row as one stream
  // (rdm/trace/first_segments.h); a recording bake traces every segment with traceVoxels. Both give
  // the same bytes, with sun and emitters, at every level and in prefiltered radiance maps.
  Scene s = mixedScene();
  s.sun = Sun{{0.4, 1.0, 0.3}, {3.0, 3.0, 3.0}, 0.5};
  s.palette.push_back({{255, 200, 120}, 7, 0, 3});  // palette index 4: an emitter
  s.blocks["lamp"] = test::blockFrom([](int x, int y, int z) { return x + y + z < 6 ? 4 : 0; });
  s.placements.push_back({{0, 1, 0}, "lamp", 0});
  BakeOptions plain, recording;
  plain.threads = recording.threads = 2;
  recording.record_slot_sets = true;
  const VoxelWorld w = buildWorld(s);
  const BakeResult a = bakeScene(w, s.bake, plain), b = bakeScene(w, s.bake, recording);
  EXPECT_TRUE(a.report.effects.sun && a.report.effects.emitters);
  EXPECT_TRUE(bitIdentical(a, b));
}

TEST(Bake, LevelsPresentAndSkipRule) {
  Scene s = mixedScene();
  VoxelWorld w = buildWorld(s);
  std::vector<RdmId> ids = listRdms(w, s.bake);
  auto has = [&](ivec3 slot, int level) {
    for (const RdmId& id : ids) {
      if (id.slot == slot && id.level == level) return true;
    }
    return false;
  };
  EXPECT_TRUE(has({0, 0, 1}, 0) && has({0, 0, 1}, 3) && has({0, 0, 1}, 7));
  EXPECT_FALSE(has({0, 0, 1}, 1));
  EXPECT_TRUE(has({1, 0, 1}, 7) && !has({1, 0, 1}, 0));
  EXPECT_EQ(ids.size(), 3u + 1u + 1u + 3u);
  for (const RdmId& id : ids) EXPECT_EQ(id.size, shared::hemisphereSize(id.level, 8));
  // The mirror block is full: the wall's -X face (towards it) is skipped; +X is not.
  EXPECT_TRUE(faceSkipped(w, {1, 0, 1}, 1));
  EXPECT_FALSE(faceSkipped(w, {1, 0, 1}, 0));
  EXPECT_FALSE(faceSkipped(w, {0, 0, 1}, 1));  // grid border: baked
}

TEST(Bake, BlockTurnedAboutYBakesToPermutedFaces) {
  // Centre block plus an east neighbour, then the whole arrangement turned 90 degrees
  // about +Y (rot 1 maps +X -> -Z): face f's maps reappear on face R(f), depth exactly,
  // radiance within the two bakes' standard errors.
  auto make = [](int rot, ivec3 neighbour) {
    Scene s = test::uniformSkyScene(3, 1, 3, 1.0);
    s.blocks["l"] =
        test::blockFrom([](int x, int y, int z) { return x > 10 || (y < 5 && z < 6) ? 1 : 0; });
    s.placements = {{{1, 0, 1}, "l", rot}, {{neighbour.x, 0, neighbour.z}, "l", rot}};
    s.bake = {32, 3, 1, 8};
    return s;
  };
  BakeResult a = bake(make(0, {2, 0, 1})), b = bake(make(1, {1, 0, 0}));
  const int face_map[6] = {5, 4, 2, 3, 0, 1};  // +X->-Z, -X->+Z, +Z->+X, -Z->-X
  auto find = [](const BakeResult& r, ivec3 slot, int level) -> const RdmData* {
    for (const RdmData& d : r.rdms) {
      if (d.id.slot == slot && d.id.level == level) return &d;
    }
    return nullptr;
  };
  const RdmData* da = find(a, {1, 0, 1}, 7);
  const RdmData* db = find(b, {1, 0, 1}, 7);
  ASSERT_TRUE(da && db);
  const int S = da->id.size;
  for (int f = 0; f < 6; ++f) {
    int g = face_map[f];
    EXPECT_EQ(da->skipped[f], db->skipped[g]);
    for (int j = 0; j < S; ++j)
      for (int i = 0; i < S; ++i) {
        glm::ivec2 pa = shared::rdmTexelPixel(0, 0, S, f, i, j),
                   pb = shared::rdmTexelPixel(0, 0, S, g, i, j);
        EXPECT_EQ(da->image.at(pa.x, pa.y, 3), db->image.at(pb.x, pb.y, 3)) << "face " << f;
        vec3 la = texel(*da, pa.x, pa.y), lb = texel(*db, pb.x, pb.y);
        vec3 tol = 4.0f * glm::sqrt(sigma(*da, pa.x, pa.y) * sigma(*da, pa.x, pa.y) +
                                    sigma(*db, pb.x, pb.y) * sigma(*db, pb.x, pb.y)) +
                   vec3(1e-6f);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(la[c], lb[c], tol[c]) << "face " << f;
      }
  }
}

TEST(Bake, TargetErrorSamplesUntilBelowTarget) {
  Scene s = mixedScene();
  s.bake.spp = 4;
  BakeOptions o;
  o.threads = 2;
  o.target_error = 0.05;
  o.max_spp_factor = 64;
  VoxelWorld w = buildWorld(s);
  BakeResult adaptive = bakeScene(w, s.bake, o), a2 = bakeScene(w, s.bake, o);
  BakeResult fixed = bake(s);
  EXPECT_LT(adaptive.report.mean_relative_error, fixed.report.mean_relative_error);
  EXPECT_TRUE(bitIdentical(adaptive, a2));  // deterministic
  // The cap holds everywhere; an RDM that never reached it has every texel below the
  // target (relative error of the stored float mean and standard error, 0.1 % slack for
  // their rounding); and the target made some texel sample beyond the base spp.
  const uint32_t cap = uint32_t(s.bake.spp * o.max_spp_factor);
  uint32_t most = 0;
  for (const RdmData& d : adaptive.rdms) {
    ASSERT_LE(d.max_samples, cap);
    most = std::max(most, d.max_samples);
    if (d.max_samples == cap) continue;
    const size_t texels = d.image.pixels.size() / 4;
    for (size_t t = 0; t < texels; ++t) {
      const float* c = &d.image.pixels[t * 4];
      const float m = luminance(glm::vec3(c[0], c[1], c[2]));
      const float e = luminance(
          glm::vec3(d.stderr_rgb[t * 3], d.stderr_rgb[t * 3 + 1], d.stderr_rgb[t * 3 + 2]));
      ASSERT_TRUE(e == 0.0f || e < o.target_error * 1.001 * m)
          << "slot " << d.id.slot.x << "," << d.id.slot.y << "," << d.id.slot.z << " level "
          << d.id.level << " texel " << t << ": " << e / m << " at " << d.max_samples << " samples";
    }
  }
  EXPECT_GT(most, uint32_t(s.bake.spp));
}

}  // namespace
}  // namespace rdm

namespace rdm {
namespace {

TEST(Bake, FirstSegmentSetIsInsideTheFullSet) {
  // docs/spec.md section 8: the full set holds every ray's slots, first segments and central rays
  // included, so fast (first-segment) rebakes can never exceed exact ones.
  Scene s = *builtinScene("chess");
  s.bake.spp = 2;
  s.bake.max_hemisphere = 8;
  BakeOptions o;
  o.threads = 2;
  o.record_slot_sets = true;
  BakeResult r = bakeScene(buildWorld(s), s.bake, o);
  for (const RdmData& d : r.rdms) {
    EXPECT_FALSE(d.first_set.empty());
    EXPECT_TRUE(
        std::includes(d.full_set.begin(), d.full_set.end(), d.first_set.begin(), d.first_set.end()))
        << "slot " << d.id.slot.x << "," << d.id.slot.y << "," << d.id.slot.z << " level "
        << d.id.level;
  }
}

}  // namespace
}  // namespace rdm
