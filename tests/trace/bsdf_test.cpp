// GGX and the BSDF at the hard cases: alpha 0, 1e-4 and 1, grazing views; albedo values
// quoted in docs/spec.md section 5.
#include <gtest/gtest.h>
#include <numbers>

#include <cmath>
#include <random>

#include "rdm/trace/bsdf.h"
#include "rdm/transport/sampling.h"

namespace rdm {
namespace {

bool finite3(glm::vec3 v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

Material dielectric(float alpha, float metallic = 0.0f) {
  Material m;
  m.base_color = glm::vec3(1.0f);
  m.metallic = metallic;
  m.alpha = alpha;
  m.f0 = glm::vec3((1.0f - metallic) * 0.04f) + metallic * m.base_color;
  return m;
}

glm::vec3 viewAt(float cos_theta) {
  return {std::sqrt(std::max(0.0f, 1.0f - cos_theta * cos_theta)), 0.0f, cos_theta};
}

TEST(Bsdf, WeightsAndPdfsFiniteAtHardCases) {
  std::mt19937 rng(2);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (float alpha : {0.0f, 1e-4f, 0.0204f, 0.5f, 1.0f})
    for (float metallic : {0.0f, 1.0f})
      for (float cos_v : {1.0f, 0.5f, 1e-3f, 1e-6f}) {
        Material m = dielectric(alpha, metallic);
        glm::vec3 v = viewAt(cos_v);
        for (int i = 0; i < 2000; ++i) {
          BsdfSample s = sampleBsdf(m, v, u(rng), u(rng), u(rng));
          if (!s.valid) continue;
          ASSERT_TRUE(finite3(s.weight)) << alpha << " " << cos_v;
          ASSERT_TRUE(std::isfinite(s.pdf) && s.pdf >= 0.0f);
          ASSERT_LE(s.weight.x, 20.0f) << "alpha " << alpha << " cos " << cos_v;
          glm::vec3 f = evalBsdf(m, v, s.l);
          ASSERT_TRUE(finite3(f));
          ASSERT_TRUE(std::isfinite(pdfBsdf(m, v, s.l)));
        }
      }
}

TEST(Bsdf, GgxTermsFiniteAtTinyAlpha) {
  for (float alpha : {1e-4f, 1e-2f, 1.0f}) {
    EXPECT_TRUE(std::isfinite(ggxD(1.0f, alpha)));
    EXPECT_TRUE(std::isfinite(ggxD(0.0f, alpha)));
    EXPECT_TRUE(std::isfinite(ggxVisibility(1e-7f, 1e-7f, alpha)));
    EXPECT_TRUE(std::isfinite(ggxG1OverCos(0.0f, alpha)));
    EXPECT_TRUE(std::isfinite(smithLambda(1e-7f, alpha)));
  }
  EXPECT_NEAR(ggxD(1.0f, 1.0f), 1.0f / kPi, 1e-6f);
}

// Directional albedo by sampling: mean of f cos / pdf (delta lobe weight included).
double albedo(const Material& m, float cos_v, int n) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  double sum = 0.0;
  glm::vec3 v = viewAt(cos_v);
  for (int i = 0; i < n; ++i) {
    BsdfSample s = sampleBsdf(m, v, u(rng), u(rng), u(rng));
    if (s.valid) sum += s.weight.x;
  }
  return sum / n;
}

TEST(Bsdf, WhiteDielectricAlbedoMatchesSpec) {
  // docs/spec.md section 5: 0.972 at normal view, 0.984 at cos 0.2 (r = 7, alpha = 1).
  EXPECT_NEAR(albedo(dielectric(1.0f), 1.0f, 400000), 0.972, 0.004);
  EXPECT_NEAR(albedo(dielectric(1.0f), 0.2f, 400000), 0.984, 0.004);
}

TEST(Bsdf, MirrorReflectsExactly) {
  Material m = dielectric(0.0f, 1.0f);
  glm::vec3 v = glm::normalize(glm::vec3(0.3f, -0.2f, 0.9f));
  BsdfSample s = sampleBsdf(m, v, 0.3f, 0.7f, 0.5f);
  ASSERT_TRUE(s.valid && s.delta);
  EXPECT_EQ(s.l, glm::vec3(-v.x, -v.y, v.z));
  EXPECT_NEAR(s.weight.x, 1.0f, 1e-6f);  // white metal: F = 1
  EXPECT_EQ(evalBsdf(m, v, s.l), glm::vec3(0.0f));
  EXPECT_FALSE(hasSmoothLobe(m));
}

TEST(Bsdf, SampledPdfMatchesEvaluatedPdf) {
  // Importance-sampled and uniformly sampled estimates of the albedo agree.
  Material m = dielectric(0.3f, 0.5f);
  glm::vec3 v = viewAt(0.6f);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  double uniform = 0.0;
  const int n = 400000;
  for (int i = 0; i < n; ++i) {
    float z = u(rng), phi = 2.0f * kPi * u(rng);
    float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    glm::vec3 l(r * std::cos(phi), r * std::sin(phi), z);
    uniform += evalBsdf(m, v, l).x * z * 2.0 * kPi;
  }
  EXPECT_NEAR(albedo(m, 0.6f, n), uniform / n, 0.01);
}

TEST(Sampling, ConeStaysInsideTinySunDisc) {
  const float half = float(std::sin(0.27 * std::numbers::pi / 360.0));
  const float one_minus_cos = 2.0f * half * half;
  for (float u0 : {0.0f, 0.5f, 0.9999999f}) {
    glm::vec3 d = sampleUniformCone(one_minus_cos, u0, 0.3f);
    EXPECT_NEAR(glm::length(d), 1.0f, 1e-6f);
    glm::vec3 e = d - glm::vec3(0, 0, 1);
    EXPECT_LE(glm::dot(e, e), 4.0f * half * half * 1.0001f);
  }
}

}  // namespace
}  // namespace rdm
