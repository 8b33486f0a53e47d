// Hemi-oct encoding, texel directions and atlas pixels (docs/spec.md section 3) against the
// independently computed vectors in tests/data/texels.json.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <random>

#include <nlohmann/json.hpp>

#include "rdm/transport/rdm_shared_cpp.h"

namespace rdm {
namespace {

using namespace rdm::shared;

bool finite2(glm::vec2 v) {
  return std::isfinite(v.x) && std::isfinite(v.y);
}

TEST(HemiOct, RoundTripRandomDirections) {
  std::mt19937 rng(1);
  std::normal_distribution<float> n(0.0f, 1.0f);
  for (int i = 0; i < 100000; ++i) {
    glm::vec3 d = glm::normalize(glm::vec3(n(rng), n(rng), std::abs(n(rng))));
    glm::vec3 back = hemiOctDecode(hemiOctEncode(d));
    ASSERT_LT(glm::length(back - d), 2e-6f);
  }
}

TEST(HemiOct, SpecialPoints) {
  EXPECT_EQ(hemiOctEncode({0, 0, 1}), glm::vec2(0, 0));
  EXPECT_EQ(hemiOctEncode({1, 0, 0}), glm::vec2(1, 1));  // corners: in-plane axes
  EXPECT_EQ(hemiOctEncode({0, 1, 0}), glm::vec2(1, -1));
  EXPECT_EQ(hemiOctEncode({0, -1, 0}), glm::vec2(-1, 1));
  EXPECT_EQ(hemiOctEncode({-1, 0, 0}), glm::vec2(-1, -1));
  glm::vec3 diag = glm::normalize(glm::vec3(1, 1, 0));  // edge midpoints: diagonals
  glm::vec2 e = hemiOctEncode(diag);
  EXPECT_NEAR(e.x, 1.0f, 1e-6f);
  EXPECT_NEAR(e.y, 0.0f, 1e-6f);
  for (float u : {-1.0f, -0.5f, 0.0f, 0.5f, 1.0f}) {  // the square's edges are the horizon
    EXPECT_NEAR(hemiOctDecode({u, 1.0f}).z, 0.0f, 1e-6f);
    EXPECT_NEAR(hemiOctDecode({1.0f, u}).z, 0.0f, 1e-6f);
    EXPECT_NEAR(glm::length(hemiOctDecode({u, -1.0f})), 1.0f, 1e-6f);
  }
}

TEST(HemiOct, BelowHorizonIsClampedNeverNan) {
  for (float z : {-1e-7f, -1e-3f, -0.5f, -1.0f}) {
    for (glm::vec3 d :
         {glm::vec3(0.6f, 0.8f, z), glm::vec3(-1.0f, 0.0f, z), glm::vec3(0.0f, 0.0f, z)}) {
      glm::vec2 e = hemiOctEncode(d);
      EXPECT_TRUE(finite2(e));
      EXPECT_LE(std::max(std::abs(e.x), std::abs(e.y)), 1.0f + 1e-6f);
      glm::vec3 back = hemiOctDecode(e);
      EXPECT_TRUE(std::isfinite(back.x) && std::isfinite(back.y) && std::isfinite(back.z));
      EXPECT_GE(back.z, 0.0f);
    }
  }
}

TEST(HemiOct, CornerTexelsPointAlongTheFrame) {
  for (int S : {2, 4, 8, 256}) {
    auto dominant = [&](int i, int j) {
      glm::vec3 d = glm::normalize(glm::vec3(texelCentralDirection(i, j, S)));
      return d;
    };
    EXPECT_LT(dominant(0, 0).x, -0.5f);         // -t
    EXPECT_GT(dominant(S - 1, 0).y, 0.5f);      // +b
    EXPECT_GT(dominant(S - 1, S - 1).x, 0.5f);  // +t
    EXPECT_LT(dominant(0, S - 1).y, -0.5f);     // -b
  }
}

TEST(HemiOct, CentralDirectionIsSTimesTheHemiOctPoint) {
  for (int S : {2, 4, 8, 16, 256})
    for (int j = 0; j < S; ++j)
      for (int i = 0; i < S; ++i) {
        glm::ivec3 d = texelCentralDirection(i, j, S);
        ASSERT_GT(d.z, 0);
        glm::vec2 uv(2.0f * (i + 0.5f) / S - 1.0f, 2.0f * (j + 0.5f) / S - 1.0f);
        glm::vec3 decoded = hemiOctDecode(uv);
        ASSERT_LT(glm::length(glm::normalize(glm::vec3(d)) - decoded), 1e-6f);
      }
}

TEST(HemiOct, KnownAnswerTexelsAndAtlasPixels) {
  std::ifstream in(std::string(RDM_TEST_DATA_DIR) + "/texels.json");
  ASSERT_TRUE(in.good());
  nlohmann::json j = nlohmann::json::parse(in);
  int count = 0;
  for (const auto& t : j["texels"]) {
    int S = t["S"], f = t["face"], i = t["i"], jj = t["j"];
    glm::ivec3 d = texelCentralDirection(i, jj, S);
    EXPECT_EQ(d, glm::ivec3(t["D_tbn"][0], t["D_tbn"][1], t["D_tbn"][2]));
    glm::vec3 world = glm::normalize(
        glm::vec3(d.x * faceTangent(f) + d.y * faceBitangent(f) + d.z * faceNormal(f)));
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(world[c], t["world_dir"][c].get<float>(), 1e-6f);
    glm::ivec2 px = rdmTexelPixel(0, 0, S, f, i, jj);
    EXPECT_EQ(px, glm::ivec2(t["atlas_pixel_in_rdm"][0], t["atlas_pixel_in_rdm"][1]));
    ++count;
  }
  EXPECT_EQ(count, 6 * (4 + 16 + 64));
}

TEST(HemiOct, FaceFramesAreRightHanded) {
  for (int f = 0; f < 6; ++f) {
    EXPECT_EQ(glm::cross(glm::vec3(faceTangent(f)), glm::vec3(faceBitangent(f))),
              glm::vec3(faceNormal(f)));
  }
}

}  // namespace
}  // namespace rdm
