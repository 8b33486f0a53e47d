// Face light (docs/spec.md sections 3.2 and 4.6): exposed faces, the furnace, occlusion and
// lamps, determinism, RGB9E5 and face_light.bin.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>

#include "rdm/bake/face_light.h"
#include "rdm/base/file_util.h"
#include "rdm/scene/lights.h"
#include "rdm/transport/rdm_shared_cpp.h"
#include "test_scenes.h"

namespace rdm {
namespace {

using glm::ivec3;
using glm::vec3;

FaceLight bakeLight(const Scene& s, int spp, int threads = 2) {
  return bakeFaceLight(buildWorld(s), s, {threads, spp});
}

Scene whiteBlocks(const std::vector<ivec3>& slots) {
  Scene s = test::uniformSkyScene(3, 3, 3, 1.0);
  s.blocks["white"].voxels.assign(4096, 1);
  for (const ivec3& slot : slots) s.placements.push_back({{slot.x, slot.y, slot.z}, "white", 0});
  return s;
}

// The light of face `face` of slot-local voxel (x, y, z), or NaN when it is not exposed.
float faceValue(const FaceLightSlot& s, int x, int y, int z, int face) {
  const uint32_t id = shared::faceLightTexel(x + 16 * y + 256 * z, face);
  for (size_t i = 0; i < s.faces.size(); ++i)
    if (s.faces[i] == id) return s.light[i].g;
  return std::numeric_limits<float>::quiet_NaN();
}

std::string tempPath(const std::string& name) {
  return testing::TempDir() + "/face_light_" + std::to_string(getpid()) + "_" + name;
}

TEST(FaceLight, ExposedFacesAreTheBlockSurfaceLessTheSharedOnes) {
  const Scene one = whiteBlocks({{1, 1, 1}});
  EXPECT_EQ(exposedFaces(buildWorld(one), {1, 1, 1}).size(), 6u * 256u);
  const Scene two = whiteBlocks({{1, 1, 1}, {2, 1, 1}});
  const VoxelWorld world = buildWorld(two);
  EXPECT_EQ(exposedFaces(world, {1, 1, 1}).size(), 5u * 256u);  // +X touches the neighbour
  EXPECT_TRUE(exposedFaces(world, {0, 0, 0}).empty());          // an empty slot
  const std::vector<uint32_t> faces = exposedFaces(world, {2, 1, 1});
  EXPECT_TRUE(std::is_sorted(faces.begin(), faces.end()));
}

TEST(FaceLight, WhiteFurnaceFacesSeeingOnlySkyAreExactlyOne) {
  const FaceLight light = bakeLight(whiteBlocks({{1, 1, 1}}), 16);
  ASSERT_EQ(light.slots.size(), 1u);
  ASSERT_EQ(light.slots[0].light.size(), 6u * 256u);
  for (const vec3& v : light.slots[0].light) EXPECT_EQ(v, vec3(1.0f));  // every path sees the sky
}

TEST(FaceLight, WhiteFurnaceInsideACarvingStaysNearOne) {
  // A block with a 4-voxel-deep pit: faces inside see mostly white walls. White at r = 7
  // reflects a little less than all the light at grazing angles (single-scatter GGX), so the
  // converged values inside are 0.92-0.97 (1024 spp; lower in the pit's corners); at 256 spp one
  // face's standard error is about 2.5 %. Bounds: every face above 0.8 and below 1.017^bounces
  // (docs/spec.md section 5), the mean over all faces (most see the sky) within 0.93..1.
  Scene s = test::uniformSkyScene(3, 3, 3, 1.0);
  s.blocks["pit"] = test::blockFrom([](int x, int y, int z) {
    return (y >= 12 && x >= 4 && x < 12 && z >= 4 && z < 12) ? 0 : 1;
  });
  s.placements = {{{1, 1, 1}, "pit", 0}};
  s.bake.max_bounces = 8;
  const FaceLight light = bakeLight(s, 256);
  double sum = 0.0;
  for (const vec3& v : light.slots[0].light) {
    EXPECT_GT(v.g, 0.8f);
    EXPECT_LT(v.g, std::pow(1.017f, 8.0f));
    sum += v.g;
  }
  const double mean = sum / double(light.slots[0].light.size());
  EXPECT_GT(mean, 0.93);
  EXPECT_LE(mean, 1.0);
}

TEST(FaceLight, FacesUnderARoofAreDarkerThanOpenOnes) {
  // A floor slab with a roof over x < 8: the floor's top faces under the roof see less sky.
  Scene s = test::uniformSkyScene(1, 1, 1, 1.0);
  s.palette = {{{128, 128, 128}, 7, 0, 0}};
  s.blocks["shelter"] =
      test::blockFrom([](int x, int y, int) { return y == 0 || (y == 4 && x < 8) ? 1 : 0; });
  s.placements = {{{0, 0, 0}, "shelter", 0}};
  const FaceLight light = bakeLight(s, 64);
  const float under = faceValue(light.slots[0], 2, 0, 8, 2),
              open = faceValue(light.slots[0], 13, 0, 8, 2);
  ASSERT_FALSE(std::isnan(under) || std::isnan(open));
  EXPECT_LT(under, 0.6f * open);
}

TEST(FaceLight, ALampLightsTheFacesBesideIt) {
  // An emissive voxel standing on a dark floor under a black sky: floor faces next to it
  // receive its light, faces far away almost none.
  Scene s = test::uniformSkyScene(1, 1, 1, 0.0);
  s.palette = {{{128, 128, 128}, 7, 0, 0}, {{255, 200, 150}, 7, 0, 3}};
  s.blocks["lamp"] = test::blockFrom(
      [](int x, int y, int z) { return y == 0 ? 1 : (y == 1 && x == 3 && z == 3 ? 2 : 0); });
  s.placements = {{{0, 0, 0}, "lamp", 0}};
  const FaceLight light = bakeLight(s, 64);
  const float near = faceValue(light.slots[0], 4, 0, 3, 2),
              far = faceValue(light.slots[0], 14, 0, 14, 2);
  EXPECT_GT(near, 0.05f);
  EXPECT_GT(near, 20.0f * far);
}

TEST(FaceLight, AnEmissiveEnclosureGivesItsRadianceToEveryFaceInside) {
  // A hollow block whose shell is emissive, traced without bounces: every inward face sees
  // emitters in every direction and nothing else, so its light is the emitters' radiance
  // exactly in expectation. A solid emissive block two slots away holds 36 % of the emitter
  // luminance, so the local emitter choice and the world's are mixed (pick factor 1.42 for the
  // shell's faces). The choice, next-event estimation and the emitters the path hits are
  // weighted by MIS; a missing or doubled weight or a wrong pick factor moves the mean by
  // 20-100 %. Tolerance: the mean over the 2,400 inward faces within 1 % (its standard error
  // at 16 spp is ~0.2 %), each face within 25 %.
  Scene s = test::uniformSkyScene(3, 1, 1, 0.0);
  s.palette = {{{255, 255, 255}, 7, 0, 3}};
  s.bake.max_bounces = 0;
  s.blocks["shell"] = test::blockFrom([](int x, int y, int z) {
    auto edge = [](int c) { return c == 0 || c == 15; };
    return edge(x) || edge(y) || edge(z) ? 1 : 0;
  });
  s.blocks["solid"] = test::blockFrom([](int, int, int) { return 1; });
  s.placements = {{{0, 0, 0}, "shell", 0}, {{2, 0, 0}, "solid", 0}};
  const VoxelWorld world = buildWorld(s);
  ASSERT_FALSE(world.emitters.empty());
  const float radiance = world.emitters.emitters[0].radiance.g;
  const FaceLight light = bakeLight(s, 16);
  double sum = 0.0;
  int inward = 0;
  for (size_t i = 0; i < light.slots[0].faces.size(); ++i) {
    const int voxel = int(light.slots[0].faces[i]) / 6, face = int(light.slots[0].faces[i]) % 6;
    const ivec3 v(voxel & 15, (voxel >> 4) & 15, voxel >> 8), in = v + shared::faceNormal(face);
    if (glm::any(glm::lessThan(in, ivec3(1))) || glm::any(glm::greaterThan(in, ivec3(14))))
      continue;
    const float value = light.slots[0].light[i].g;
    EXPECT_NEAR(value, radiance, 0.25f * radiance) << "face " << light.slots[0].faces[i];
    sum += value;
    ++inward;
  }
  ASSERT_EQ(inward, 6 * 14 * 14);
  EXPECT_NEAR(sum / inward, radiance, 0.01 * radiance);
}

// The face light's noise where lamps light a scene: the scene lit by its emitters alone (black
// sky, no sun), baked with seeds 1 and 2; the RMS difference of the faces' luminances over their
// RMS mean (dominated by the faces the lamps light brightly).
double lampNoise(Scene scene, int spp) {
  scene.sky = Sky{glm::dvec3(0.0), glm::dvec3(0.0), glm::dvec3(0.0)};
  scene.sun.reset();
  const VoxelWorld world = buildWorld(scene);
  FaceLightOptions options{2, spp};
  BakeSettings settings = scene.bake;
  double diff2 = 0.0, mean2 = 0.0;
  settings.seed = 1;
  options.settings = settings;
  const FaceLight a = bakeFaceLight(world, scene, options);
  settings.seed = 2;
  options.settings = settings;
  const FaceLight b = bakeFaceLight(world, scene, options);
  for (size_t s = 0; s < a.slots.size(); ++s)
    for (size_t i = 0; i < a.slots[s].faces.size(); ++i) {
      const double la = luminance(a.slots[s].light[i]), lb = luminance(b.slots[s].light[i]);
      diff2 += (la - lb) * (la - lb);
      mean2 += 0.25 * (la + lb) * (la + lb);
    }
  return std::sqrt(diff2 / mean2);
}

TEST(FaceLight, NextEventEstimationKeepsTheNoiseNearLampsLow) {
  // island's lamp posts at its default spp (8).
  const Scene island = builtinScene("island").value();
  const double noise = lampNoise(island, island.face_light_spp);
  std::printf("island lamp light noise at %d spp: %.4f\n", island.face_light_spp, noise);
  // 2026-12-07: 1.401 without next-event estimation, 0.996 with the world's emitter choice,
  // 0.769 with the local one.
  EXPECT_LT(noise, 0.9);
}

TEST(FaceLight, TheSameBitsWhateverTheThreadCount) {
  Scene s = test::randomVoxelScene(2, 2, 2, 0.3, 7);
  const FaceLight one = bakeLight(s, 4, 1), two = bakeLight(s, 4, 2);
  ASSERT_EQ(one.slots.size(), two.slots.size());
  for (size_t i = 0; i < one.slots.size(); ++i) {
    EXPECT_EQ(one.slots[i].faces, two.slots[i].faces);
    ASSERT_EQ(one.slots[i].light.size(), two.slots[i].light.size());
    EXPECT_EQ(0, std::memcmp(one.slots[i].light.data(), two.slots[i].light.data(),
                             one.slots[i].light.size() * sizeof(vec3)));
  }
}

bool sameBits(const FaceLightSlot& a, const FaceLightSlot& b) {
  return a.slot == b.slot && a.faces == b.faces && a.light.size() == b.light.size() &&
         std::memcmp(a.light.data(), b.light.data(), a.light.size() * sizeof(vec3)) == 0;
}

TEST(FaceLight, AnEditReBakesTheChangedSlotsAndTheNeighboursItExposes) {
  Scene s = whiteBlocks({{0, 0, 0}, {1, 1, 1}, {2, 1, 1}});
  const VoxelWorld before = buildWorld(s);
  FaceLight light = bakeFaceLight(before, s, {2, 4});
  const FaceLight original = light;
  s.placements.pop_back();  // (2, 1, 1) removed: (1, 1, 1)'s +X face is exposed now
  const VoxelWorld after = buildWorld(s);
  EXPECT_EQ(updateFaceLight(before, after, s.bake, light, 2), (std::vector<ivec3>{{1, 1, 1}}));
  const FaceLight full = bakeFaceLight(after, s, {2, 4});
  ASSERT_EQ(light.slots.size(), 2u);
  EXPECT_TRUE(sameBits(light.slots[0], original.slots[0]));  // (0, 0, 0): kept as it was
  EXPECT_TRUE(sameBits(light.slots[1], full.slots[1]));      // re-baked: a full bake's bits
  EXPECT_EQ(light.slots[1].faces.size(), 6u * 256u);
  // Painting (recolouring) a voxel re-bakes that slot only: its faces are unchanged.
  s.palette.push_back({{255, 0, 0}, 7, 0, 0});
  s.blocks["red"] = s.blocks["white"];
  s.blocks["red"].voxels[0] = 2;
  s.placements[0].block = "red";
  EXPECT_EQ(updateFaceLight(after, buildWorld(s), s.bake, light, 2),
            (std::vector<ivec3>{{0, 0, 0}}));
}

TEST(FaceLight, Rgb9e5KeepsNineBitsAndClampsTheRest) {
  for (float v : {1e-3f, 0.37f, 1.0f, 3.5f, 1000.0f, 60000.0f}) {
    const vec3 in(v, 0.5f * v, 0.25f * v);
    const vec3 out = shared::decodeRgb9e5(encodeRgb9e5(in));
    EXPECT_NEAR(out.r, in.r, in.r * (1.0f / 512.0f)) << v;  // half a step of 2^-8 of the largest
    EXPECT_NEAR(out.b, in.b, in.r * (1.0f / 512.0f)) << v;
  }
  EXPECT_EQ(shared::decodeRgb9e5(encodeRgb9e5(vec3(1e9f, 0.0f, 0.0f))).r, 65408.0f);
  EXPECT_EQ(shared::decodeRgb9e5(encodeRgb9e5(vec3(std::nanf(""), -1.0f, 0.0f))), vec3(0.0f));
  EXPECT_EQ(encodeRgb9e5(vec3(0.0f)), 0u);
  EXPECT_EQ(shared::decodeRgb9e5(encodeRgb9e5(vec3(1.0f))), vec3(1.0f));
}

TEST(FaceLight, FileRoundTripsTheEncodedValues) {
  Scene s = test::randomVoxelScene(2, 1, 2, 0.3, 3);
  const FaceLight light = bakeLight(s, 2);
  const std::string path = tempPath("round.bin");
  ASSERT_TRUE(writeFaceLight(path, light).ok());
  auto read = readFaceLight(path);
  ASSERT_TRUE(read.ok()) << read.error();
  EXPECT_EQ(read->scene_digest, light.scene_digest);
  EXPECT_EQ(read->spp, 2u);
  ASSERT_EQ(read->slots.size(), light.slots.size());
  for (size_t i = 0; i < light.slots.size(); ++i) {
    EXPECT_EQ(read->slots[i].slot, light.slots[i].slot);
    EXPECT_EQ(read->slots[i].faces, light.slots[i].faces);
    for (size_t f = 0; f < light.slots[i].light.size(); ++f)
      EXPECT_EQ(read->slots[i].light[f],
                shared::decodeRgb9e5(encodeRgb9e5(light.slots[i].light[f])));
  }
}

TEST(FaceLight, BadFilesAreRefusedNamingWhatIsWrong) {
  const FaceLight light = bakeLight(whiteBlocks({{1, 1, 1}}), 1);
  const std::string path = tempPath("bad.bin");
  ASSERT_TRUE(writeFaceLight(path, light).ok());
  std::string bytes = *readFileToString(path);
  auto refused = [&](const std::string& contents, const std::string& what) {
    EXPECT_TRUE(writeFileAtomic(path, contents).ok());
    auto r = readFaceLight(path);
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.error().find(what), std::string::npos) << r.error();
  };
  refused("RDMATLAS" + bytes.substr(8), "magic");
  std::string v1 = bytes, v4 = bytes;
  v1[8] = 1, v4[8] = 4;
  refused(v1, "version 1, this build reads 2 and 3: bake again");  // the digest had the settings
  refused(v4, "version 4");
  refused(bytes.substr(0, bytes.size() - 3), "checksum");  // torn: the trailing XXH3 is not it
  refused(bytes + "x", "checksum");
  // Version 2 (no trailing checksum) still reads, unverified, with its own structural checks.
  std::string v2 = bytes.substr(0, bytes.size() - 8);
  v2[8] = 2;
  refused(v2.substr(0, v2.size() - 3), "truncated");
  refused(v2 + "x", "trailing");
  ASSERT_TRUE(writeFileAtomic(path, v2).ok());
  EXPECT_TRUE(readFaceLight(path).ok());
  EXPECT_FALSE(readFaceLight(tempPath("missing.bin")).ok());
}

// Every single-bit flip anywhere in a version 3 file is refused as damaged (kCorrupt), so
// a base job's damaged face light never seeds a later job's.
TEST(FaceLight, AFlippedBitAnywhereIsRefusedAsCorrupt) {
  const FaceLight light = bakeLight(whiteBlocks({{1, 1, 1}}), 1);
  const std::string path = tempPath("flip.bin");
  ASSERT_TRUE(writeFaceLight(path, light).ok());
  const std::string bytes = *readFileToString(path);
  for (size_t i = 12; i < bytes.size(); i += 7) {  // past the magic and version
    std::string flipped = bytes;
    flipped[i] = char(flipped[i] ^ (1 << (i % 8)));
    auto r = decodeFaceLight(flipped, "flip.bin");
    ASSERT_FALSE(r.ok()) << "byte " << i;
    EXPECT_EQ(r.status().code(), StatusCode::kCorrupt) << r.error();
  }
  EXPECT_TRUE(decodeFaceLight(bytes, "flip.bin").ok());
}

}  // namespace
}  // namespace rdm
