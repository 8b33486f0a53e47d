// CPU preparation of everything the renderer uploads for a scene: one greedy mesh per
// unique oriented block, instances sorted by block (one indexed draw per block), the
// per-voxel [r, g, b, m] words and the per-slot RDM lookup table.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "gpu_layout.h"
#include "mesher.h"
#include "rdm/atlas.h"
#include "rdm/face_light.h"
#include "rdm/image.h"
#include "rdm/scene.h"
#include "rdm/world.h"

namespace rdm::viewer {

struct BlockDraw {
  uint32_t first_index = 0, index_count = 0;
  int32_t vertex_offset = 0;
  uint32_t first_instance = 0, instance_count = 0;
};

struct SceneGpuData {
  std::vector<MeshVertex> vertices;
  std::vector<uint32_t> indices;
  std::vector<glm::ivec4> instances;  // slot xyz, oriented block; grouped by block
  std::vector<BlockDraw> draws;       // one per oriented block with instances and quads
  // 4096 words per oriented block (r | g << 8 | b << 16 | m << 24), then per block the
  // 64-bit mask of its non-empty 4^3 bricks (VoxelWorld::occupancy) as two words, low first.
  std::vector<uint32_t> voxels;
  int quads = 0;
};

// The docs/spec.md section 1 voxel word of palette index p (0 = empty), from the scene's palette.
uint32_t voxelWord(const Scene& scene, uint8_t palette_index);

SceneGpuData buildSceneGpuData(const Scene& scene, const VoxelWorld& world);

// Slot table for `layout` (may be empty: no RDMs). `pages` are the atlas pages (R, G, B, Z)
// from which the level-7 central depths are read for docs/spec.md section 6's drop rule.
std::vector<SlotInfo> buildSlotInfos(const VoxelWorld& world, const AtlasLayout& layout,
                                     const std::vector<Image>& pages);

// The face light's texel buffer (viewer/shaders/face_light.glsl): word s (s < slot count,
// linear slot index) is 1 + the slot's row, 0 without face light; row r's 4096 voxel words
// at slot count + 4096 r are (index of the voxel's first face value) << 6 | exposed-face
// mask; the RGB9E5 face values follow. A slot whose baked faces differ from the world's
// exposed faces (edited since the bake) gets no row.
std::vector<uint32_t> buildFaceLightWords(const VoxelWorld& world, const FaceLight& light);

}  // namespace rdm::viewer
