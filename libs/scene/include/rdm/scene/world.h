// The compiled scene the transport walks: slots point at oriented blocks whose voxels are
// already rotated into slot space (each (block, rot) pair once), and per-palette materials.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "rdm/scene/lights.h"
#include "rdm/scene/scene.h"

namespace rdm {

struct Material {
  glm::vec3 base_color{0.0f};  // linear
  glm::vec3 emission{0.0f};    // radiance
  glm::vec3 f0{0.04f};         // (1 - m) 0.04 + m c
  float metallic = 0.0f;
  float alpha = 1.0f;  // GGX alpha = (r/7)^2
  int roughness = 7;
  bool emissive = false;
  float transmission = 0.0f;  // glass: the fraction of hits that meet the dielectric
  float ior = 1.5f;
};

struct OrientedBlock {
  std::array<uint8_t, 4096> voxels{};  // palette index in slot space, 0 = empty
  int solid_count = 0;
  uint8_t level_mask = 0;           // bit r set when a solid voxel has roughness level r
  std::array<bool, 6> face_full{};  // the 16x16 layer touching face f is all solid
  std::string name;
  int rot = 0;
};

// Occupancy of one oriented block for the walk (docs/performance.md): bit
// b = bx | by << 2 | bz << 4 of `bricks` is set when 4^3 brick (bx, by, bz) has a solid
// voxel; bit x | y << 2 | z << 4 of voxels[b] is set when voxel (x, y, z) of brick b is solid.
struct BrickMasks {
  uint64_t bricks = 0;
  std::array<uint64_t, 64> voxels{};
};

// VoxelWorld::slot_steps values of empty slots, and the words of a BrickMasks.
constexpr int32_t kEmptySlot = -1;
constexpr int32_t kEmptySlotGroup = -2;
constexpr int32_t kOccupancyWords = int32_t(sizeof(BrickMasks) / 4);

struct VoxelWorld {
  glm::ivec3 size{0};          // slots
  std::vector<int32_t> slots;  // oriented block index, -1 when the slot is empty
  std::vector<OrientedBlock> blocks;
  std::vector<BrickMasks> occupancy;  // per oriented block, from its voxels
  // Per slot, what the walks' empty-space steps read (one 32-bit lookup, which
  // traceVoxelStream gathers): the first 32-bit word of the slot's BrickMasks in `occupancy`
  // (block * kOccupancyWords) when the slot holds a block, else kEmptySlot, or kEmptySlotGroup
  // when every slot of its 2 x 2 x 2 group (slots 2 g .. 2 g + 1) inside the grid is empty.
  std::vector<int32_t> slot_steps;
  std::array<Material, 256> materials{};
  SkyLight sky;
  SunLight sun;
  EmitterList emitters;
  glm::vec3 ambient{0.0f};

  glm::ivec3 voxelExtent() const { return size * 16; }
  bool slotInGrid(const glm::ivec3& s) const {
    return s.x >= 0 && s.y >= 0 && s.z >= 0 && s.x < size.x && s.y < size.y && s.z < size.z;
  }
  int slotLinear(const glm::ivec3& s) const { return s.x + size.x * (s.y + size.y * s.z); }
  int32_t blockAt(const glm::ivec3& s) const { return slotInGrid(s) ? slots[slotLinear(s)] : -1; }
  // Palette index of a global voxel, 0 outside the grid or when empty.
  uint8_t voxelAt(const glm::ivec3& v) const;
};

VoxelWorld buildWorld(const Scene& scene);
// Whether a voxel of the world is glass (Material::transmission > 0): the path tracer then
// runs its glass code, which only the CPU backend has.
bool hasGlass(const VoxelWorld& world);
// The voxels of `block` placed with rotation `rot` (0..23), in slot space.
std::array<uint8_t, 4096> orientedVoxels(const Block& block, int rot);
BrickMasks brickMasks(const OrientedBlock& block);
float srgbToLinear(int value);

}  // namespace rdm
