// The prefiltered estimator (docs/spec.md section 3.1): every level of a face is derived from
// one traced radiance map of that face, as Filament's cmgen derives the roughness levels of an
// environment map. The map is a level-0 estimate (texel-footprint averages) at the size of the
// finest level the block has; rough levels are fixed sparse kernels over the map's box-filtered
// mip chain (GGX prefiltered importance sampling with Hammersley points). The diffuse level
// comes from the map's own samples (bake.cpp).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

namespace rdm {

// A face's incoming radiance, hemi-oct S x S (S a power of two) with its mip chain. Each texel
// holds the mean RGB and the variance of that mean.
class RadianceMap {
 public:
  explicit RadianceMap(int size);
  int size() const { return size_; }
  void set(int i, int j, const glm::vec3& mean, const glm::vec3& variance);
  glm::vec3 mean(int i, int j) const { return mean_[size_t(j) * size_ + i]; }
  glm::vec3 variance(int i, int j) const { return variance_[size_t(j) * size_ + i]; }
  // For a map of one sample per texel, whose own variance is unknown: each texel takes the
  // sample variance of its 2 x 2 block (an overestimate where the radiance itself varies).
  void estimateVarianceFromBlocks();
  // Fills mips 1.. from mip 0 (2 x 2 box: mean of means, variance / 4 of the mean variance).
  void buildMips();
  // Every texel of every mip, mip 0 first (mipOffset).
  std::span<const glm::vec3> means() const { return {mean_.data(), texels_}; }
  std::span<const glm::vec3> variances() const { return {variance_.data(), texels_}; }

 private:
  int size_;
  size_t texels_;  // of all mips
  // Mips concatenated, mip 0 first, then one texel of padding: applyKernel loads 4 floats
  // from any texel's first.
  std::vector<glm::vec3> mean_, variance_;
};

// Offset of mip m in a RadianceMap of size S's concatenated storage.
uint32_t mipOffset(int size, int mip);

struct KernelTap {
  uint32_t texel;  // index into the RadianceMap's concatenated mips
  float weight;
};

// One output level's kernel: taps of output texel t are taps[begin[t] .. begin[t + 1]),
// weights summing to 1 (no taps: the texel sees no valid direction and stays 0).
struct PrefilterKernel {
  std::vector<uint32_t> begin;
  std::vector<KernelTap> taps;
};

// The kernel of rough `level` (1..6) at hemisphere size `size` over a map of size
// `base_size` (>= size).
// Built once per process and shared; thread-safe.
const PrefilterKernel& prefilterKernel(int level, int size, int base_size);

// Output texel t of `kernel` over `map`: mean and the variance of that mean.
void applyKernel(const PrefilterKernel& kernel, const RadianceMap& map, int texel, glm::vec3& mean,
                 glm::vec3& variance);

}  // namespace rdm
