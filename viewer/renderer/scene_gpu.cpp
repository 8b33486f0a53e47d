#include "scene_gpu.h"

#include <unordered_set>

#include "rdm/bake/bake.h"
#include "rdm/bake/face_light_filter.h"
#include "rdm/base/check.h"

namespace rdm::viewer {

uint32_t voxelWord(const Scene& scene, uint8_t palette_index) {
  if (palette_index == 0 || palette_index > scene.palette.size()) return 0;
  const PaletteEntry& e = scene.palette[palette_index - 1];
  const uint32_t m = shared::packMaterial(e.roughness, e.metallic, e.emission);
  return uint32_t(e.color[0]) | uint32_t(e.color[1]) << 8 | uint32_t(e.color[2]) << 16 | m << 24;
}

namespace {

// Key of a point in world voxel units (slot * 16 + slot voxel units; 21 bits per axis).
uint64_t worldPointKey(const glm::ivec4& slot, const glm::ivec3& p) {
  const glm::ivec3 w = 16 * glm::ivec3(slot) + p;
  return uint64_t(uint32_t(w.x)) | uint64_t(uint32_t(w.y)) << 21 | uint64_t(uint32_t(w.z)) << 42;
}

// Every slot's copy of its block's mesh, watertight against the slots around it: a quad edge
// on the slot's boundary is split where any slot has a rectangle corner.
void appendSlotMeshes(const VoxelWorld& world,
                      const std::vector<std::vector<glm::ivec4>>& per_block, SceneGpuData& data) {
  std::vector<std::vector<MeshQuad>> quads(per_block.size());
  std::unordered_set<uint64_t> corners;
  for (size_t b = 0; b < per_block.size(); ++b) {
    if (per_block[b].empty()) continue;
    quads[b] = greedyQuads(world.blocks[b].voxels);
    const std::vector<glm::ivec3> on_boundary = boundaryCorners(quads[b]);
    for (const glm::ivec4& slot : per_block[b])
      for (const glm::ivec3& c : on_boundary) corners.insert(worldPointKey(slot, c));
  }
  for (size_t b = 0; b < per_block.size(); ++b) {
    if (quads[b].empty()) continue;
    for (const glm::ivec4& slot : per_block[b]) {
      const BlockMesh mesh = watertightMesh(quads[b], [&](const glm::ivec3& p) {
        return corners.count(worldPointKey(slot, p)) != 0;
      });
      const uint32_t base = uint32_t(data.vertices.size());
      data.vertices.insert(data.vertices.end(), mesh.vertices.begin(), mesh.vertices.end());
      data.instances.insert(data.instances.end(), mesh.vertices.size(), slot);
      for (uint32_t i : mesh.indices) data.indices.push_back(base + i);
      data.quads += mesh.quadCount();
    }
    data.slots_drawn += int(per_block[b].size());
  }
}

}  // namespace

SceneGpuData buildSceneGpuData(const Scene& scene, const VoxelWorld& world) {
  SceneGpuData data;
  std::vector<std::vector<glm::ivec4>> per_block(world.blocks.size());
  for (int k = 0; k < world.size.z; ++k)
    for (int j = 0; j < world.size.y; ++j)
      for (int i = 0; i < world.size.x; ++i) {
        const int32_t b = world.blockAt({i, j, k});
        if (b >= 0) per_block[b].push_back({i, j, k, b});
      }
  const size_t block_count = world.blocks.size();
  RDM_CHECK(world.occupancy.size() == block_count);
  data.voxels.resize(block_count * (shared::kBlockVoxelCount + 2));
  for (size_t b = 0; b < block_count; ++b) {
    for (int v = 0; v < 4096; ++v)
      data.voxels[b * 4096 + v] = voxelWord(scene, world.blocks[b].voxels[v]);
    const uint64_t bricks = world.occupancy[b].bricks;
    data.voxels[block_count * 4096 + 2 * b] = uint32_t(bricks);
    data.voxels[block_count * 4096 + 2 * b + 1] = uint32_t(bricks >> 32);
  }
  appendSlotMeshes(world, per_block, data);
  if (!data.indices.empty()) {
    BlockDraw all;
    all.index_count = uint32_t(data.indices.size());
    all.instance_count = 1;
    data.draws.push_back(all);
  }
  return data;
}

namespace {

// A tile the shader can name: stored, on a page below kNoTilePage, at an even corner.
bool tileNamed(const FaceTile& t) {
  return t.stored() && t.page < kNoTilePage && t.x % 2 == 0 && t.y % 2 == 0;
}

// Level `level` of `info` (gpu_layout.h): its size and tile words. A size the shader cannot
// encode (not a power of two) leaves the level absent; a tile it cannot name is left
// unstored. The entry's tiles lie on the pages (tilesFit).
void setTiles(const AtlasEntry& e, SlotInfo& info) {
  const int size = e.id.size, level = e.id.level;
  if (size < 2 || (size & (size - 1)) != 0) return;
  info.header.w |= __builtin_ctz(unsigned(size)) << (4 * level);
  for (int f = 0; f < 6; ++f) {
    const FaceTile& t = e.faces[size_t(f)];
    const uint32_t word = tileNamed(t)
                              ? uint32_t(t.x / 2) | uint32_t(t.y / 2) << 13 | uint32_t(t.page) << 26
                              : uint32_t(kNoTilePage) << 26;
    info.tiles[(6 * level + f) / 4][(6 * level + f) % 4] = int32_t(word);
  }
}

}  // namespace

void AtlasDepthMask::reset(int layers, int width, int height) {
  width_ = width, height_ = height, words_per_row_ = (width + 63) / 64;
  layers_.assign(size_t(layers), std::vector<uint64_t>(size_t(words_per_row_) * size_t(height)));
}

void AtlasDepthMask::write(int layer, int x, int y, const Image& texels) {
  RDM_CHECK(layer >= 0 && layer < layers() && x >= 0 && y >= 0 &&
            (texels.channels == 4 || texels.channels == 1) && x + texels.width <= width_ &&
            y + texels.height <= height_);
  std::vector<uint64_t>& bits = layers_[size_t(layer)];
  const size_t stride = size_t(texels.channels);
  for (int j = 0; j < texels.height; ++j) {
    uint64_t* row = &bits[size_t(y + j) * size_t(words_per_row_)];
    const float* z = &texels.pixels[(size_t(j) * size_t(texels.width) + 1) * stride - 1];
    for (int i = 0; i < texels.width; ++i) {
      const int c = x + i;
      const uint64_t bit = uint64_t(1) << (c & 63);
      if (z[size_t(i) * stride] != 0.0f)
        row[c >> 6] |= bit;
      else
        row[c >> 6] &= ~bit;
    }
  }
}

void AtlasDepthMask::clear(int layer, int x, int y, int w, int h) {
  RDM_CHECK(layer >= 0 && layer < layers() && x >= 0 && y >= 0 && x + w <= width_ &&
            y + h <= height_);
  std::vector<uint64_t>& bits = layers_[size_t(layer)];
  for (int j = y; j < y + h; ++j)
    for (int c = x; c < x + w; ++c)
      bits[size_t(j) * size_t(words_per_row_) + size_t(c >> 6)] &= ~(uint64_t(1) << (c & 63));
}

bool AtlasDepthMask::any(int layer, int x, int y, int w, int h) const {
  if (layer < 0 || layer >= layers() || x < 0 || y < 0 || x + w > width_ || y + h > height_)
    return false;
  const std::vector<uint64_t>& bits = layers_[size_t(layer)];
  for (int j = y; j < y + h; ++j)
    for (int c = x; c < x + w; ++c) {
      if (bits[size_t(j) * size_t(words_per_row_) + size_t(c >> 6)] >> (c & 63) & 1u) return true;
    }
  return false;
}

void AtlasDepthMask::copyFrom(const AtlasDepthMask& other, int layer, int w, int h) {
  RDM_CHECK(layer < layers() && layer < other.layers() && w <= width_ && w <= other.width_ &&
            h <= height_ && h <= other.height_);
  for (int j = 0; j < h; ++j)
    for (int c = 0; c < w; ++c) {
      const uint64_t bit = uint64_t(1) << (c & 63);
      const bool set =
          other.layers_[size_t(layer)][size_t(j) * size_t(other.words_per_row_) + size_t(c >> 6)] &
          bit;
      uint64_t& word = layers_[size_t(layer)][size_t(j) * size_t(words_per_row_) + size_t(c >> 6)];
      word = set ? word | bit : word & ~bit;
    }
}

size_t AtlasDepthMask::bytes() const {
  return layers_.size() * size_t(words_per_row_) * size_t(height_) * sizeof(uint64_t);
}

std::vector<SlotInfo> buildSlotInfos(const VoxelWorld& world, const AtlasLayout& layout,
                                     const std::vector<AtlasPage>& page_sizes,
                                     const AtlasDepthMask& depth) {
  std::vector<SlotInfo> slots(world.slots.size());
  for (int k = 0; k < world.size.z; ++k)
    for (int j = 0; j < world.size.y; ++j)
      for (int i = 0; i < world.size.x; ++i) {
        const glm::ivec3 s(i, j, k);
        SlotInfo& info = slots[world.slotLinear(s)];
        info.header.x = world.blockAt(s);
        if (info.header.x < 0) continue;
        for (int f = 0; f < 6; ++f) {
          if (faceSkipped(world, s, f)) info.header.z |= 1 << f;
        }
      }
  for (const AtlasEntry& e : layout.entries) {
    const int level = e.id.level;
    if (world.blockAt(e.id.slot) < 0 || level < 0 || level >= shared::kLevelCount) continue;
    if (!tilesFit(e, page_sizes)) continue;
    SlotInfo& info = slots[world.slotLinear(e.id.slot)];
    setTiles(e, info);
    if (level != shared::kDiffuseLevel) continue;
    for (int f = 0; f < 6; ++f) {
      const FaceTile& t = e.faces[size_t(f)];
      // Usable when the tile's central depths are not all 0.
      if (tileNamed(t) && depth.any(t.page, t.x, t.y, e.id.size, e.id.size))
        info.header.y |= 1 << f;
    }
  }
  return slots;
}

std::vector<uint32_t> buildFaceLightWords(const VoxelWorld& world, const FaceLight& light) {
  const size_t slot_count = size_t(world.size.x) * world.size.y * world.size.z;
  std::vector<uint32_t> words(slot_count, 0u);
  std::vector<size_t> rows;
  for (size_t r = 0; r < light.slots.size(); ++r) {
    const FaceLightSlot& s = light.slots[r];
    if (world.slotInGrid(s.slot) && s.faces == exposedFaces(world, s.slot)) rows.push_back(r);
  }
  size_t value = slot_count + rows.size() * shared::kBlockVoxelCount;
  words.resize(value, 0u);
  const FaceLight filtered = filterFaceLight(world, light);
  std::vector<uint32_t> filtered_words;
  for (size_t r = 0; r < rows.size(); ++r) {
    const FaceLightSlot& s = light.slots[rows[r]];
    words[size_t(world.slotLinear(s.slot))] = uint32_t(r + 1);
    const size_t row = slot_count + r * shared::kBlockVoxelCount;
    for (size_t i = 0; i < s.faces.size(); ++i) {
      const uint32_t voxel = s.faces[i] / shared::kFaceCount,
                     face = s.faces[i] % shared::kFaceCount;
      uint32_t& word = words[row + voxel];
      if ((word & 63u) == 0u) word = uint32_t(value + i) << 6;  // faces are sorted per voxel
      word |= 1u << face;
      words.push_back(encodeRgb9e5(s.light[i]));
      filtered_words.push_back(encodeRgb9e5(filtered.slots[rows[r]].light[i]));
    }
    value += s.faces.size();
  }
  RDM_CHECK(words.size() == value && value < (size_t(1) << 26));
  words.insert(words.end(), filtered_words.begin(), filtered_words.end());
  words.push_back(uint32_t(filtered_words.size()));
  return words;
}

}  // namespace rdm::viewer
