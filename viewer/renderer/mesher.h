// Greedy meshing of one oriented block (voxels already in slot space, docs/spec.md section 1).
// Only faces between a solid voxel and an empty voxel of the same block (or the block's
// border) are emitted; coplanar faces with the same normal are merged into rectangles
// regardless of material, since the fragment shader looks the material up per voxel.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace rdm::viewer {

// One vertex: integer position in slot voxel units (0..16 per axis), the docs/spec.md face index of
// its quad's normal, and twice its quad's centre (so .5 centres stay integer).
struct MeshVertex {
  uint32_t position_face;  // x | y << 8 | z << 16 | face << 24
  uint32_t center2;        // 2cx | 2cy << 8 | 2cz << 16
};

struct BlockMesh {
  std::vector<MeshVertex> vertices;  // 4 per quad
  std::vector<uint32_t> indices;     // 6 per quad, counter-clockwise seen from outside
  int quadCount() const { return int(vertices.size() / 4); }
};

// `voxels`: palette indices (0 = empty), index x + 16 y + 256 z.
BlockMesh greedyMesh(const std::array<uint8_t, 4096>& voxels);

// Decoders for tests and the CPU side (the vertex shader decodes the same layout).
inline int vertexCoord(const MeshVertex& v, int axis) {
  return int((v.position_face >> (8 * axis)) & 0xffu);
}
inline int vertexFace(const MeshVertex& v) {
  return int(v.position_face >> 24);
}

}  // namespace rdm::viewer
