// Radical inverses (van der Corput, Halton) and the Owen-scrambled 2D Sobol points of
// shaders/shared/rdm_sobol.h (docs/spec.md section 3.1), which the Vulkan kernel compiles too.
#pragma once

#include <cstdint>

#include "shared/rdm_sobol.h"

namespace rdm {

inline uint32_t reverseBits(uint32_t x) {
  return shared::sobolReverseBits(x);
}

// Radical inverse of `index` in base 2 (the van der Corput sequence, Sobol dimension 0),
// exact in float for index < 2^24.
inline float radicalInverse2(uint32_t index) {
  return float(reverseBits(index) >> 8) * (1.0f / 16777216.0f);
}

// Radical inverse of `index` in `base` >= 2: the Halton sequence's coordinate of that base.
inline float radicalInverse(uint32_t base, uint32_t index) {
  const float inverse = 1.0f / float(base);
  float scale = inverse, result = 0.0f;
  for (; index > 0; index /= base, scale *= inverse) result += float(index % base) * scale;
  return result;
}

struct Point2 {
  float u0, u1;  // in [0, 1)
};

// Sample `index` of the scrambled sequence with key `seed`.
inline Point2 owenSobol2(uint32_t index, uint32_t seed) {
  const glm::vec2 p = shared::owenSobolPoint(index, seed);
  return {p.x, p.y};
}

}  // namespace rdm
