// The face light's reconstruction filter (docs/spec.md section 6, "Face light filter"): a
// face's filtered value is a weighted mean of the exposed faces of the same direction in its
// plane, so the noise of a few paths per face averages out where the light is smooth. Two
// edge stops keep real detail: a face whose light differs from the centre's by much more
// than the expected noise of `spp` paths weighs less (lamp pools, light through a gap), and
// so does a face with other solid voxels in front of it (corners, the foot of a wall).
#pragma once

#include "rdm/bake/face_light.h"
#include "rdm/scene/world.h"

namespace rdm {

// Defaults chosen by measurement (docs/results.md section 1i).
struct FaceLightFilter {
  int radius = 3;          // voxels on each side in the face's plane; 0 returns the light as is
  float sigma = 1.5f;      // spatial Gaussian's standard deviation, voxels
  float range = 1.0f;      // luminance kernel width in units of 1 / sqrt(spp) of the larger
                           // luminance; 0 turns the luminance stop off
  float occupancy = 1.0f;  // occupancy kernel width in solid voxels in front (of 18); 0: off
  int threads = 0;         // 0: all cores; the result does not depend on it
};

// `light` filtered over `world`. Slots whose faces are not `world`'s exposed ones (a light
// of another scene version, which the viewer drops) are copied unchanged and lend no
// neighbours. Deterministic: the same inputs give the same bits.
FaceLight filterFaceLight(const VoxelWorld& world, const FaceLight& light,
                          const FaceLightFilter& filter = {});

}  // namespace rdm
