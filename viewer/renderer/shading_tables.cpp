#include "shading_tables.h"

#include <algorithm>
#include <cmath>

#include "rdm/trace/bsdf.h"
#include "rdm/transport/rdm_shared_cpp.h"
#include "rdm/transport/sampling.h"
#include "rdm/transport/sobol.h"

namespace rdm::viewer {
namespace {

glm::vec3 viewDirection(float mu) {
  return {std::sqrt(std::max(0.0f, 1.0f - mu * mu)), 0.0f, mu};
}

float pow5(float x) {
  return x * x * x * x * x;
}

}  // namespace

glm::vec2 integrateDfg(float alpha, float mu, int samples) {
  if (alpha <= 0.0f) {  // mirror: the delta lobe reflects F(n.v)
    const float fc = pow5(1.0f - mu);
    return {1.0f - fc, fc};
  }
  const glm::vec3 v = viewDirection(mu);
  double a = 0.0, b = 0.0;
  for (int i = 0; i < samples; ++i) {
    const glm::vec3 h =
        sampleGgxNdf(alpha, (float(i) + 0.5f) / float(samples), radicalInverse2(uint32_t(i)));
    const float v_dot_h = glm::dot(v, h);
    const glm::vec3 l = 2.0f * v_dot_h * h - v;
    if (l.z <= 0.0f || v_dot_h <= 0.0f || h.z <= 0.0f) continue;
    // f cos / pdf with f = D V F, pdf(l) = D n.h / (4 v.h): 4 V n.l (v.h) / (n.h) times F.
    const float weight = 4.0f * ggxVisibility(mu, l.z, alpha) * l.z * v_dot_h / h.z;
    const float fc = pow5(1.0f - v_dot_h);
    a += (1.0f - fc) * weight;
    b += fc * weight;
  }
  return {float(a / samples), float(b / samples)};
}

float integrateDiffuseAlbedo(float mu, int samples) {
  const glm::vec3 v = viewDirection(mu);
  double c = 0.0;
  for (int i = 0; i < samples; ++i) {
    // Cosine-distributed l: pdf = cos / pi cancels the lobe's cos / pi.
    const float u0 = (float(i) + 0.5f) / float(samples), u1 = radicalInverse2(uint32_t(i));
    const glm::vec3 l = sampleCosineHemisphere(u0, u1);
    const glm::vec3 h = glm::normalize(v + l);
    c += 1.0f - pow5(1.0f - std::max(0.0f, glm::dot(v, h)));
  }
  return float(c / samples);
}

ShadingTables computeShadingTables(int samples) {
  ShadingTables tables;
  tables.dfg.resize(size_t(kDfgRows) * kDfgColumns);
  std::vector<float> albedo(kDfgColumns);
  for (int c = 0; c < kDfgColumns; ++c) {
    albedo[c] = integrateDiffuseAlbedo((float(c) + 0.5f) / kDfgColumns, samples);
  }
  for (int level = 0; level < kDfgRows; ++level) {
    const float alpha = shared::roughnessAlpha(level);
    for (int c = 0; c < kDfgColumns; ++c) {
      const glm::vec2 ab = integrateDfg(alpha, (float(c) + 0.5f) / kDfgColumns, samples);
      tables.dfg[size_t(level) * kDfgColumns + c] = glm::vec4(ab, albedo[c], 0.0f);
    }
  }
  return tables;
}

glm::vec4 ShadingTables::lookup(int level, float mu) const {
  const float x = std::clamp(mu * kDfgColumns - 0.5f, 0.0f, float(kDfgColumns - 1));
  const int c0 = int(x), c1 = std::min(c0 + 1, kDfgColumns - 1);
  return glm::mix(at(level, c0), at(level, c1), x - float(c0));
}

}  // namespace rdm::viewer
