// Measures of an atlas against a reference atlas of the same scene (docs/denoise.md): the
// error of its texels and the difference between neighbouring blocks, which is where a seam
// shows. Both are luminance sums over texels, level by level.
#pragma once

#include <array>
#include <cstddef>

#include "rdm/atlas/atlas.h"

namespace rdm {

struct LuminanceSums {
  double difference = 0.0;  // sum of |luminance differences|
  double value = 0.0;       // sum of the luminances compared against
  size_t texels = 0;
  double relative() const { return value > 0 ? difference / value : 0.0; }
};
using LevelSums = std::array<LuminanceSums, 8>;  // by roughness level

// Over the texels of every face that both atlases store, for RDMs both hold (same slot, level
// and size) and texels with a reference depth above 0: |lum(a) - lum(ref)| against lum(ref).
LevelSums atlasError(const LoadedAtlas& a, const LoadedAtlas& ref);

// Over every pair of RDMs of `atlas` at the same level and size in slots side by side in a
// face's plane, both storing that face: |lum(one) - lum(other)| texel by texel (the same
// direction from origins one unit apart) against their mean. A filter that treats block
// borders differently from the inside of a face raises it above what the reference shows.
LevelSums borderDifference(const LoadedAtlas& atlas);

}  // namespace rdm
