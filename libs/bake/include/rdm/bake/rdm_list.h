// Which RDMs a scene needs (docs/spec.md section 3), in canonical order, and what one baked RDM
// holds. Below the bake itself so that the atlas and the stores need not include the bake API.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <tuple>
#include <vector>

#include <glm/glm.hpp>

#include "rdm/image/image.h"
#include "rdm/scene/scene.h"
#include "rdm/scene/world.h"

namespace rdm {

struct RdmId {
  glm::ivec3 slot{0};
  int level = 7;
  int size = 2;  // hemisphere size S; the image is 2S x 3S
  bool operator==(const RdmId&) const = default;
};

// An RDM's place, whatever its size: (slot x, y, z, level), ordered for std::map.
using SlotLevelKey = std::tuple<int, int, int, int>;
inline SlotLevelKey slotLevelKey(const glm::ivec3& slot, int level) {
  return {slot.x, slot.y, slot.z, level};
}

// Canonical order: size descending, then slot (i, j, k) lexicographic, then level.
bool canonicalLess(const RdmId& a, const RdmId& b);

// Every RDM of the scene: level 7 and each roughness level present per non-empty slot.
std::vector<RdmId> listRdms(const VoxelWorld& world, const BakeSettings& settings);
size_t countRdms(const VoxelWorld& world);  // listRdms(world, any).size(), without the list
// Section 3's skip rule: the neighbour across face f is in the grid and its touching
// layer is all solid.
bool faceSkipped(const VoxelWorld& world, const glm::ivec3& slot, int face);

// The level whose radiance map the faces of `slot`'s block share under the prefiltered
// estimator (docs/spec.md section 3.1): the block's finest rough level; -1 when the block has
// none (diffuse only) or the naive estimator runs.
int radianceMapLevel(const VoxelWorld& world, const BakeSettings& settings, const glm::ivec3& slot);

struct RdmData {
  RdmId id;
  Image image;                    // 2S x 3S, channels R, G, B, Z
  std::vector<float> stderr_rgb;  // per texel, 3 floats: estimated standard error
  std::array<bool, 6> skipped{};
  uint32_t max_samples = 0;  // most samples any texel took (target-error mode)
  // With BakeOptions::record_slot_sets: sorted linear slot indices met by any ray (full set)
  // and by first segments and central rays (first-segment set), docs/spec.md section 8.
  std::vector<uint32_t> full_set, first_set;
  bool smooth_vertex = false;  // some path met a non-delta vertex
};

struct EffectSet {
  bool sun = false;
  bool emitters = false;
  bool metals = false;
  bool glass = false;  // a palette material with transmission (rdm/trace/glass.h)
  uint8_t levels = 0;  // bit r: roughness level r present
  std::string describeSimulated() const;
  std::string describeSkipped() const;
};
EffectSet sceneEffects(const VoxelWorld& world);

}  // namespace rdm
