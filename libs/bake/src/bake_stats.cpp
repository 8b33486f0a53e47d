#include "rdm/bake/bake_stats.h"

#include <algorithm>
#include <cmath>

#include "rdm/scene/lights.h"
#include "rdm/transport/rdm_shared_cpp.h"

namespace rdm {

void storeRadiance(RdmData& rdm, int face, int i, int j, const glm::dvec3& mean,
                   const glm::dvec3& err) {
  const glm::ivec2 px = shared::rdmTexelPixel(0, 0, rdm.id.size, face, i, j);
  for (int c = 0; c < 3; ++c) {
    rdm.image.at(px.x, px.y, c) = float(mean[c]);
    rdm.stderr_rgb[(size_t(px.y) * rdm.image.width + px.x) * 3 + c] = float(err[c]);
  }
}

double SampleEstimator::relativeError() const {
  double m = luminance(glm::vec3(mean())), e = luminance(glm::vec3(stderror()));
  return m > 0.0 ? e / m : (e > 0.0 ? INFINITY : 0.0);
}

uint64_t usefulTexels(const std::vector<RdmData>& rdms) {
  uint64_t texels = 0;
  for (const RdmData& rdm : rdms) {
    const uint64_t face = uint64_t(rdm.id.size) * uint64_t(rdm.id.size);
    for (bool skipped : rdm.skipped) texels += skipped ? 0 : face;
  }
  return texels;
}

RdmErrorStats rdmErrorStats(const RdmData& rdm) {
  RdmErrorStats stats;
  stats.texels = uint64_t(rdm.image.width) * uint64_t(rdm.image.height);
  const int S = rdm.id.size;
  for (int y = 0; y < rdm.image.height; ++y)
    for (int x = 0; x < rdm.image.width; ++x) {
      if (rdm.skipped[size_t((y / S) * 2 + x / S)]) continue;
      size_t p = size_t(y) * rdm.image.width + x;
      glm::vec3 value(rdm.image.pixels[p * 4], rdm.image.pixels[p * 4 + 1],
                      rdm.image.pixels[p * 4 + 2]);
      glm::vec3 err(rdm.stderr_rgb[p * 3], rdm.stderr_rgb[p * 3 + 1], rdm.stderr_rgb[p * 3 + 2]);
      float lum = luminance(value);
      if (lum <= 0.0f) continue;
      double rel = luminance(err) / lum;
      stats.sum += rel, ++stats.count;
      stats.max = std::max(stats.max, rel);
    }
  return stats;
}

void summariseBake(const std::vector<RdmErrorStats>& rdms, BakeReport& report) {
  double sum = 0.0;
  uint64_t count = 0;
  for (const RdmErrorStats& r : rdms) {
    report.texels += r.texels;
    sum += r.sum, count += r.count;
    report.max_relative_error = std::max(report.max_relative_error, r.max);
  }
  report.mean_relative_error = count ? sum / double(count) : 0.0;
}

void summariseBake(const std::vector<RdmData>& rdms, BakeReport& report) {
  std::vector<RdmErrorStats> stats;
  stats.reserve(rdms.size());
  for (const RdmData& rdm : rdms) stats.push_back(rdmErrorStats(rdm));
  summariseBake(stats, report);
}

}  // namespace rdm
