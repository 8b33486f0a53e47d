// Greedy meshing of one oriented block (voxels already in slot space, docs/spec.md section 1).
// Only faces between a solid voxel and an empty voxel of the same block (or the block's
// border) are emitted; coplanar faces with the same normal are merged into rectangles
// regardless of material, since the fragment shader looks the material up per voxel.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <glm/glm.hpp>
#include <vector>

namespace rdm::viewer {

// One vertex: integer position in slot voxel units (0..16 per axis), the docs/spec.md face index of
// its quad's normal, and twice its quad's centre (so .5 centres stay integer).
struct MeshVertex {
  uint32_t position_face;  // x | y << 8 | z << 16 | face << 24
  uint32_t center2;        // 2cx | 2cy << 8 | 2cz << 16
};

// A merged rectangle of face `face`'s exposed faces in voxel layer `layer`: cells [u0, u1) x
// [v0, v1) along the face's (tangent, bitangent) axes (rdm_shared.h's faceTangent/Bitangent).
struct MeshQuad {
  int face = 0, layer = 0, u0 = 0, v0 = 0, u1 = 0, v1 = 0;
};

struct BlockMesh {
  std::vector<MeshVertex> vertices;
  std::vector<uint32_t> indices;  // triangles, counter-clockwise seen from outside
  int quad_count = 0;             // greedy rectangles the triangles cover
  int quadCount() const { return quad_count; }
  int triangleCount() const { return int(indices.size() / 3); }
};

// `voxels`: palette indices (0 = empty), index x + 16 y + 256 z.
std::vector<MeshQuad> greedyQuads(const std::array<uint8_t, 4096>& voxels);

// Each greedy rectangle as 4 vertices and 2 triangles (vertices 4q..4q+3, corners in (t, b)
// order). Has T-junctions: a long edge passes through the corners of shorter neighbours.
BlockMesh greedyMesh(const std::array<uint8_t, 4096>& voxels);

// Whether an edge lying on the block's boundary, where other blocks' surfaces may meet it, is
// split at point `p` (slot voxel units, some coordinate 0 or 16). Exact when it holds wherever
// any slot's mesh has a rectangle corner and adjacent slots answer alike for a shared point (a
// point split on one side only would be a T-junction on the other).
using BoundarySplit = std::function<bool(const glm::ivec3& p)>;

// The same rectangles without T-junctions, so that rasterising leaves no cracks: every edge is
// split at each rectangle corner of the block lying inside it and, where the edge lies on the
// block's boundary, where `split` says. A split rectangle is fanned from an integer interior
// point, or zipped between its long sides when it is one voxel thin; an unsplit one stays 4
// vertices and 2 triangles. Positions are integers, so slot + position / 16 is exact in float
// and the meshes of adjacent slots meet bit-identically.
BlockMesh watertightMesh(const std::vector<MeshQuad>& quads, const BoundarySplit& split);
// Split at every integer point of the boundary: exact against neighbours meshed the same way.
BlockMesh watertightMesh(const std::array<uint8_t, 4096>& voxels);

// The rectangles' corners on the block's boundary (some coordinate 0 or 16), slot voxel units.
std::vector<glm::ivec3> boundaryCorners(const std::vector<MeshQuad>& quads);

// Decoders for tests and the CPU side (the vertex shader decodes the same layout).
inline int vertexCoord(const MeshVertex& v, int axis) {
  return int((v.position_face >> (8 * axis)) & 0xffu);
}
inline int vertexFace(const MeshVertex& v) {
  return int(v.position_face >> 24);
}

}  // namespace rdm::viewer
