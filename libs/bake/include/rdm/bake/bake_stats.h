// Per-texel statistics shared by the CPU and Vulkan bakes, so both report noise the same way.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "rdm/bake/bake.h"

namespace rdm {

// Weighted-mean estimator with its standard error: R = sum w L / sum w,
// var(R) = sum w^2 (L - R)^2 / (sum w)^2. Sums in double, in the order samples arrive.
struct SampleEstimator {
  glm::dvec3 sum_wl{0.0}, sum_w2l{0.0}, sum_w2l2{0.0};
  double sum_w = 0.0, sum_w2 = 0.0;

  void add(const glm::vec3& l, float weight) {
    glm::dvec3 ld(l);
    double w = weight;
    sum_w += w, sum_w2 += w * w;
    sum_wl += w * ld, sum_w2l += w * w * ld, sum_w2l2 += w * w * ld * ld;
  }
  glm::dvec3 mean() const { return sum_w > 0.0 ? sum_wl / sum_w : glm::dvec3(0.0); }
  glm::dvec3 stderror() const {
    if (sum_w <= 0.0) return glm::dvec3(0.0);
    glm::dvec3 r = mean();
    glm::dvec3 var = (sum_w2l2 - 2.0 * r * sum_w2l + r * r * sum_w2) / (sum_w * sum_w);
    return glm::sqrt(glm::max(var, glm::dvec3(0.0)));
  }
  // Luminance of the standard error over luminance of the mean; 0 for an exact zero.
  double relativeError() const;
};

// Slot field of the random-number key (docs/spec.md section 5): i | j << 8 | k << 16.
inline uint32_t slotKey(const glm::ivec3& s) {
  return uint32_t(s.x) | uint32_t(s.y) << 8 | uint32_t(s.z) << 16;
}

// Texel (i, j) of face `face` of `rdm`: the RGB mean and its standard error (the depth is
// the caller's), as both backends store them.
void storeRadiance(RdmData& rdm, int face, int i, int j, const glm::dvec3& mean,
                   const glm::dvec3& err);

// Texels of faces that were baked (not skipped): the part of an atlas that carries light.
uint64_t usefulTexels(const std::vector<RdmData>& rdms);

// One RDM's share of BakeReport's texels and relative standard error over its baked texels.
struct RdmErrorStats {
  uint64_t texels = 0;  // of the 2S x 3S image
  double sum = 0.0;     // of relative errors
  uint64_t count = 0;   // texels with a positive luminance
  double max = 0.0;
};
RdmErrorStats rdmErrorStats(const RdmData& rdm);

// Fills report.texels and the mean / max relative standard error over baked texels, summed
// per RDM, then over the RDMs in order (so a bake that frees RDMs as they finish agrees).
void summariseBake(const std::vector<RdmErrorStats>& rdms, BakeReport& report);
void summariseBake(const std::vector<RdmData>& rdms, BakeReport& report);

}  // namespace rdm
