// A face's radiance map of the prefiltered estimator (docs/spec.md section 3.1) and the two
// steps every backend shares: building the map from its texels' sample sums, and deriving an
// RDM face's texels from it. The CPU bake (bake.cpp) and the Vulkan bake (vulkan_bake_batches.cpp)
// trace the map's samples their own way and hand them here, so both derive the same levels.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "rdm/bake/bake_stats.h"
#include "rdm/bake/prefilter.h"

namespace rdm {

struct FaceMap {
  std::unique_ptr<RadianceMap> map;
  glm::vec3 diffuse{0.0f}, diffuse_variance{0.0f};  // level 7 from the map's samples
  std::vector<uint32_t> full_set, first_set;        // sorted slot sets of the map's paths
  bool smooth_vertex = false;
  uint32_t max_samples = 0;
};

// One map texel's samples weighted by cos(theta) dw / (du dv) at their footprint points, for
// level 7 (the diffuse mean) from the map's own samples.
struct CosineSums {
  glm::dvec3 lit{0.0};  // sum of L cos(theta) dw / (du dv)
  double weight = 0.0;  // sum of cos(theta) dw / (du dv)

  // A sample of radiance `l` at hemi-oct point `uv` ([-1, 1]^2; texelFootprintPoint).
  void add(const glm::vec2& uv, const glm::vec3& l);
};

// Collects a map's texels (any order) and finishes the map once all are in.
class FaceMapBuilder {
 public:
  explicit FaceMapBuilder(int size);
  int size() const { return size_; }
  // Texel (i, j): its estimate over `samples` samples and their cosine sums.
  void setTexel(int i, int j, const SampleEstimator& e, uint32_t samples, const CosineSums& cosine);
  // The map with its mips, level 7 and max_samples; with one sample per texel, each texel's
  // variance from its 2 x 2 block (RadianceMap::estimateVarianceFromBlocks).
  void finish(FaceMap& out);

 private:
  int size_;
  std::unique_ptr<RadianceMap> map_;
  std::vector<double> texel_weight_;  // sum of cos(theta) dw / (du dv) per sample
  glm::dvec3 lit_{0.0};
  double weight_ = 0.0;
  uint32_t max_samples_ = 0;
};

// Derives the texels of one S x S face of roughness `level` from its face's map: level 0 is
// the map (S = the map's size), rough levels its prefilter kernels, level 7 the diffuse mean.
class FaceMapDerivation {
 public:
  FaceMapDerivation(const FaceMap& map, int level, int size);
  // Texel (i, j): the mean and the variance of the mean.
  void texel(int i, int j, glm::vec3& mean, glm::vec3& variance) const;

 private:
  const FaceMap& map_;
  const int level_, size_;
  const PrefilterKernel* kernel_;  // rough levels only
};

}  // namespace rdm
