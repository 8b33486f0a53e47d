#include "mesher.h"

#include "rdm/transport/rdm_shared_cpp.h"

namespace rdm::viewer {
namespace {

namespace sh = rdm::shared;

bool solidAt(const std::array<uint8_t, 4096>& voxels, int x, int y, int z) {
  if (x < 0 || y < 0 || z < 0 || x > 15 || y > 15 || z > 15) return false;
  return voxels[x + 16 * y + 256 * z] != 0;
}

// Emits the quad of face f covering layer cells [u0, u1) x [v0, v1) along the face's
// (tangent, bitangent) axes, at the layer's outer plane.
void emitQuad(BlockMesh& mesh, int face, int layer, int u0, int v0, int u1, int v1) {
  const glm::ivec3 n = sh::faceNormal(face), t = sh::faceTangent(face), b = sh::faceBitangent(face);
  const int n_axis = face / 2;
  const int t_axis = t.x != 0 ? 0 : (t.y != 0 ? 1 : 2);
  const int b_axis = b.x != 0 ? 0 : (b.y != 0 ? 1 : 2);
  const int plane = layer + (n[n_axis] > 0 ? 1 : 0);
  // Corners in (t, b) order: (0,0), (1,0), (1,1), (0,1). Since t x b = n, this order is
  // counter-clockwise seen from outside when t and b point along +axes; a negative axis
  // direction mirrors the winding, which the sign product below undoes.
  const int us[4] = {u0, u1, u1, u0}, vs[4] = {v0, v0, v1, v1};
  glm::ivec3 center2(0);
  center2[n_axis] = 2 * plane;
  center2[t_axis] = u0 + u1;
  center2[b_axis] = v0 + v1;
  const uint32_t c = uint32_t(center2.x) | uint32_t(center2.y) << 8 | uint32_t(center2.z) << 16;
  const uint32_t base = uint32_t(mesh.vertices.size());
  for (int k = 0; k < 4; ++k) {
    glm::ivec3 p(0);
    p[n_axis] = plane;
    p[t_axis] = us[k];
    p[b_axis] = vs[k];
    mesh.vertices.push_back(
        {uint32_t(p.x) | uint32_t(p.y) << 8 | uint32_t(p.z) << 16 | uint32_t(face) << 24, c});
  }
  const bool flip = (t[t_axis] * b[b_axis]) < 0;
  const uint32_t ccw[6] = {0, 1, 2, 0, 2, 3}, cw[6] = {0, 2, 1, 0, 3, 2};
  for (uint32_t k : flip ? cw : ccw) mesh.indices.push_back(base + k);
}

// Cell (u, v) of layer `layer` in face f's (t, b) axes, as a voxel position.
glm::ivec3 layerCell(int face, int layer, int u, int v) {
  const glm::ivec3 t = sh::faceTangent(face), b = sh::faceBitangent(face);
  glm::ivec3 p(0);
  p[face / 2] = layer;
  p[t.x != 0 ? 0 : (t.y != 0 ? 1 : 2)] = u;
  p[b.x != 0 ? 0 : (b.y != 0 ? 1 : 2)] = v;
  return p;
}

void meshLayer(const std::array<uint8_t, 4096>& voxels, int face, int layer, BlockMesh& mesh) {
  const glm::ivec3 n = sh::faceNormal(face);
  bool mask[16][16];
  for (int v = 0; v < 16; ++v) {
    for (int u = 0; u < 16; ++u) {
      const glm::ivec3 p = layerCell(face, layer, u, v), q = p + n;
      mask[v][u] = solidAt(voxels, p.x, p.y, p.z) && !solidAt(voxels, q.x, q.y, q.z);
    }
  }
  for (int v = 0; v < 16; ++v) {
    for (int u = 0; u < 16;) {
      if (!mask[v][u]) {
        ++u;
        continue;
      }
      int u1 = u + 1;
      while (u1 < 16 && mask[v][u1]) ++u1;
      int v1 = v + 1;
      while (v1 < 16) {
        bool row_full = true;
        for (int k = u; k < u1; ++k) row_full = row_full && mask[v1][k];
        if (!row_full) break;
        ++v1;
      }
      for (int vv = v; vv < v1; ++vv)
        for (int k = u; k < u1; ++k) mask[vv][k] = false;
      emitQuad(mesh, face, layer, u, v, u1, v1);
      u = u1;
    }
  }
}

}  // namespace

BlockMesh greedyMesh(const std::array<uint8_t, 4096>& voxels) {
  BlockMesh mesh;
  for (int face = 0; face < 6; ++face) {
    for (int layer = 0; layer < 16; ++layer) meshLayer(voxels, face, layer, mesh);
  }
  return mesh;
}

}  // namespace rdm::viewer
