// CPU preparation of everything the renderer uploads for a scene: each slot's watertight mesh of
// its oriented block (greedy rectangles once per block, their edges split per slot against the
// neighbours, mesher.h), all in one vertex buffer drawn by one indexed draw (a draw costs lavapipe
// about 64 kB of copied state, so one draw per block made the frame grow with the world), the
// per-voxel [r, g, b, m] words and the per-slot RDM lookup table.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "gpu_layout.h"
#include "mesher.h"
#include "rdm/atlas/atlas.h"
#include "rdm/bake/face_light.h"
#include "rdm/image/image.h"
#include "rdm/scene/scene.h"
#include "rdm/scene/world.h"

namespace rdm::viewer {

struct BlockDraw {
  uint32_t first_index = 0, index_count = 0;
  int32_t vertex_offset = 0;
  uint32_t first_instance = 0, instance_count = 0;
};

struct SceneGpuData {
  std::vector<MeshVertex> vertices;  // every slot's copy of its block's mesh
  std::vector<uint32_t> indices;
  std::vector<glm::ivec4> instances;  // per vertex: its slot xyz and oriented block
  std::vector<BlockDraw> draws;       // one draw of every vertex (none without quads)
  int slots_drawn = 0;                // non-empty slots with quads
  // 4096 words per oriented block (r | g << 8 | b << 16 | m << 24), then per block the
  // 64-bit mask of its non-empty 4^3 bricks (VoxelWorld::occupancy) as two words, low first.
  std::vector<uint32_t> voxels;
  int quads = 0;
};

// The docs/spec.md section 1 voxel word of palette index p (0 = empty), from the scene's palette.
uint32_t voxelWord(const Scene& scene, uint8_t palette_index);

SceneGpuData buildSceneGpuData(const Scene& scene, const VoxelWorld& world);

// One bit per atlas texel: Z != 0. All the slot table needs of the texels (docs/spec.md
// section 6's drop rule), so the viewer keeps no CPU copy of the pages: 1/64 of the pages'
// bytes at half. Every layer is width x height bits (the device image's size); texels
// never written read as 0.
class AtlasDepthMask {
 public:
  void reset(int layers, int width, int height);
  int layers() const { return int(layers_.size()); }
  // Sets the bits of `texels` (Z: channel 3 of a 4-channel image, or a 1-channel image) at
  // (x, y) of `layer`.
  void write(int layer, int x, int y, const Image& texels);
  // Clears the bits of a rect (texels that became zero).
  void clear(int layer, int x, int y, int w, int h);
  // True when any texel of the rect has Z != 0.
  bool any(int layer, int x, int y, int w, int h) const;
  // Copies `other`'s bits in the rect (0, 0)-(w, h) of `layer` into the same place here.
  void copyFrom(const AtlasDepthMask& other, int layer, int w, int h);
  size_t bytes() const;

 private:
  int width_ = 0, height_ = 0, words_per_row_ = 0;
  std::vector<std::vector<uint64_t>> layers_;
};

// Slot table for `layout` (may be empty: no RDMs). `pages` are the sizes of the atlas pages
// the device holds (tiles outside them are left out) and `depth` their Z != 0 bits, from
// which the level-7 central depths are judged for docs/spec.md section 6's drop rule.
std::vector<SlotInfo> buildSlotInfos(const VoxelWorld& world, const AtlasLayout& layout,
                                     const std::vector<AtlasPage>& pages,
                                     const AtlasDepthMask& depth);

// The face light's texel buffer (viewer/shaders/face_light.glsl): word s (s < slot count,
// linear slot index) is 1 + the slot's row, 0 without face light; row r's 4096 voxel words
// at slot count + 4096 r are (index of the voxel's first face value) << 6 | exposed-face
// mask; the F RGB9E5 face values follow, then the same F faces' values after
// filterFaceLight (rdm/bake/face_light_filter.h), then one word F, so a shader reaches a
// face's filtered value at its index + F. A slot whose baked faces differ from the world's
// exposed faces (edited since the bake) gets no row.
std::vector<uint32_t> buildFaceLightWords(const VoxelWorld& world, const FaceLight& light);

}  // namespace rdm::viewer
