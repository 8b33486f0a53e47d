#include "rdm/bake/face_map.h"

#include <algorithm>
#include <cmath>

#include "rdm/base/check.h"
#include "rdm/transport/rdm_shared_cpp.h"

namespace rdm {
namespace {

// cos(theta) dw / (du dv) at hemi-oct point uv: dw = du dv / (2 |p|^3), cos = p.z / |p|.
double cosineSolidAngleDensity(const glm::vec2& uv) {
  const double px = 0.5 * (double(uv.x) + uv.y), py = 0.5 * (double(uv.x) - uv.y);
  const double pz = 1.0 - std::abs(px) - std::abs(py);
  if (pz <= 0.0) return 0.0;
  const double len = std::sqrt(px * px + py * py + pz * pz);
  return pz / (2.0 * len * len * len * len);
}

}  // namespace

void CosineSums::add(const glm::vec2& uv, const glm::vec3& l) {
  const double c = cosineSolidAngleDensity(uv);
  lit += c * glm::dvec3(l), weight += c;
}

FaceMapBuilder::FaceMapBuilder(int size)
    : size_(size),
      map_(std::make_unique<RadianceMap>(size)),
      texel_weight_(size_t(size) * size, 0.0) {}

void FaceMapBuilder::setTexel(int i, int j, const SampleEstimator& e, uint32_t samples,
                              const CosineSums& cosine) {
  RDM_CHECK(samples > 0);
  const glm::dvec3 se = e.stderror();
  map_->set(i, j, glm::vec3(e.mean()), glm::vec3(se * se));
  max_samples_ = std::max(max_samples_, samples);
  lit_ += cosine.lit / double(samples), weight_ += cosine.weight / double(samples);
  texel_weight_[size_t(j) * size_ + i] = cosine.weight / double(samples);
}

void FaceMapBuilder::finish(FaceMap& out) {
  if (max_samples_ == 1) map_->estimateVarianceFromBlocks();
  glm::dvec3 var(0.0);
  for (int j = 0; j < size_; ++j)
    for (int i = 0; i < size_; ++i) {
      const double w = texel_weight_[size_t(j) * size_ + i];
      var += w * w * glm::dvec3(map_->variance(i, j));
    }
  if (weight_ > 0.0) {
    out.diffuse = glm::vec3(lit_ / weight_);
    out.diffuse_variance = glm::vec3(var / (weight_ * weight_));
  }
  map_->buildMips();
  out.map = std::move(map_);
  out.max_samples = max_samples_;
}

FaceMapDerivation::FaceMapDerivation(const FaceMap& map, int level, int size)
    : map_(map),
      level_(level),
      size_(size),
      kernel_(level == 0 || level == shared::kDiffuseLevel
                  ? nullptr
                  : &prefilterKernel(level, size, map.map->size())) {
  RDM_CHECK(level != 0 || size == map.map->size());
}

void FaceMapDerivation::texel(int i, int j, glm::vec3& mean, glm::vec3& variance) const {
  if (kernel_) {
    applyKernel(*kernel_, *map_.map, j * size_ + i, mean, variance);
  } else if (level_ == shared::kDiffuseLevel) {
    mean = map_.diffuse, variance = map_.diffuse_variance;
  } else {
    mean = map_.map->mean(i, j), variance = map_.map->variance(i, j);
  }
}

}  // namespace rdm
