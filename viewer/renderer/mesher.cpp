#include "mesher.h"

#include <algorithm>
#include <bitset>
#include <cstddef>

#include "rdm/transport/rdm_shared_cpp.h"

namespace rdm::viewer {
namespace {

namespace sh = rdm::shared;

constexpr int kSize = 16;  // voxels per block edge; vertex coordinates run 0..kSize

bool solidAt(const std::array<uint8_t, 4096>& voxels, int x, int y, int z) {
  if (x < 0 || y < 0 || z < 0 || x >= kSize || y >= kSize || z >= kSize) return false;
  return voxels[x + 16 * y + 256 * z] != 0;
}

int axisOf(const glm::ivec3& d) {
  return d.x != 0 ? 0 : (d.y != 0 ? 1 : 2);
}

// Cell (u, v) of layer `layer` in face f's (t, b) axes, as a voxel position.
glm::ivec3 layerCell(int face, int layer, int u, int v) {
  glm::ivec3 p(0);
  p[face / 2] = layer;
  p[axisOf(sh::faceTangent(face))] = u;
  p[axisOf(sh::faceBitangent(face))] = v;
  return p;
}

// The rectangle's plane: its layer's outer side.
int quadPlane(const MeshQuad& q) {
  return q.layer + (sh::faceNormal(q.face)[q.face / 2] > 0 ? 1 : 0);
}

// Point (u, v) of the rectangle's plane, in slot voxel units.
glm::ivec3 quadPoint(const MeshQuad& q, int u, int v) {
  glm::ivec3 p = layerCell(q.face, 0, u, v);
  p[q.face / 2] = quadPlane(q);
  return p;
}

// Rectangles whose (t, b) corner order is clockwise seen from outside: a tangent or bitangent
// along a negative axis mirrors the winding.
bool windingFlipped(int face) {
  const glm::ivec3 t = sh::faceTangent(face), b = sh::faceBitangent(face);
  return t[axisOf(t)] * b[axisOf(b)] < 0;
}

void meshLayer(const std::array<uint8_t, 4096>& voxels, int face, int layer,
               std::vector<MeshQuad>& quads) {
  const glm::ivec3 n = sh::faceNormal(face);
  bool mask[kSize][kSize];
  for (int v = 0; v < kSize; ++v) {
    for (int u = 0; u < kSize; ++u) {
      const glm::ivec3 p = layerCell(face, layer, u, v), q = p + n;
      mask[v][u] = solidAt(voxels, p.x, p.y, p.z) && !solidAt(voxels, q.x, q.y, q.z);
    }
  }
  for (int v = 0; v < kSize; ++v) {
    for (int u = 0; u < kSize;) {
      if (!mask[v][u]) {
        ++u;
        continue;
      }
      int u1 = u + 1;
      while (u1 < kSize && mask[v][u1]) ++u1;
      int v1 = v + 1;
      while (v1 < kSize) {
        bool row_full = true;
        for (int k = u; k < u1; ++k) row_full = row_full && mask[v1][k];
        if (!row_full) break;
        ++v1;
      }
      for (int vv = v; vv < v1; ++vv)
        for (int k = u; k < u1; ++k) mask[vv][k] = false;
      quads.push_back({face, layer, u, v, u1, v1});
      u = u1;
    }
  }
}

// Appends the triangles of one rectangle through its vertices in the (u, v) plane, sharing
// each position once. Triangles are given counter-clockwise in (u, v).
class QuadEmitter {
 public:
  QuadEmitter(BlockMesh& mesh, const MeshQuad& q) : mesh_(mesh), quad_(q) {
    glm::ivec3 c2 = quadPoint(q, q.u0 + q.u1, q.v0 + q.v1);
    c2[q.face / 2] *= 2;
    center2_ = uint32_t(c2.x) | uint32_t(c2.y) << 8 | uint32_t(c2.z) << 16;
    flipped_ = windingFlipped(q.face);
  }

  void triangle(glm::ivec2 a, glm::ivec2 b, glm::ivec2 c) {
    uint32_t ia = vertex(a), ib = vertex(b), ic = vertex(c);
    if (flipped_) std::swap(ib, ic);
    mesh_.indices.insert(mesh_.indices.end(), {ia, ib, ic});
  }

 private:
  uint32_t vertex(glm::ivec2 uv) {
    for (const auto& [known, index] : known_)
      if (known == uv) return index;
    const glm::ivec3 p = quadPoint(quad_, uv.x, uv.y);
    const uint32_t index = uint32_t(mesh_.vertices.size());
    mesh_.vertices.push_back(
        {uint32_t(p.x) | uint32_t(p.y) << 8 | uint32_t(p.z) << 16 | uint32_t(quad_.face) << 24,
         center2_});
    known_.push_back({uv, index});
    return index;
  }

  BlockMesh& mesh_;
  const MeshQuad& quad_;
  uint32_t center2_ = 0;
  bool flipped_ = false;
  std::vector<std::pair<glm::ivec2, uint32_t>> known_;
};

// Positions (slot voxel units) that are a corner of some rectangle of the block.
class CornerSet {
 public:
  explicit CornerSet(const std::vector<MeshQuad>& quads) {
    for (const MeshQuad& q : quads)
      for (const glm::ivec2 uv : {glm::ivec2(q.u0, q.v0), glm::ivec2(q.u1, q.v0),
                                  glm::ivec2(q.u1, q.v1), glm::ivec2(q.u0, q.v1)})
        bits_.set(index(quadPoint(q, uv.x, uv.y)));
  }
  bool contains(const glm::ivec3& p) const { return bits_.test(index(p)); }

 private:
  static size_t index(const glm::ivec3& p) {
    return size_t(p.x + (kSize + 1) * (p.y + (kSize + 1) * p.z));
  }
  std::bitset<(kSize + 1) * (kSize + 1) * (kSize + 1)> bits_;
};

bool onBoundary(int c) {
  return c == 0 || c == kSize;
}

// Whether the edge point `p`, inside an edge along `axis`, splits that edge: it is a corner of
// the block, or the edge lies on the block's boundary where a neighbour's corner may sit.
bool splitsEdge(const CornerSet& corners, const BoundarySplit& split, const glm::ivec3& p,
                int axis) {
  if (corners.contains(p)) return true;
  for (int a = 0; a < 3; ++a) {
    if (a != axis && onBoundary(p[a])) return split(p);
  }
  return false;
}

// The rectangle's boundary, counter-clockwise in (u, v) from (u0, v0), with the split points.
std::vector<glm::ivec2> boundaryLoop(const MeshQuad& q, const CornerSet& corners,
                                     const BoundarySplit& split) {
  const glm::ivec2 c[4] = {{q.u0, q.v0}, {q.u1, q.v0}, {q.u1, q.v1}, {q.u0, q.v1}};
  const int axes[2] = {axisOf(sh::faceTangent(q.face)), axisOf(sh::faceBitangent(q.face))};
  std::vector<glm::ivec2> loop;
  for (int e = 0; e < 4; ++e) {
    const glm::ivec2 from = c[e], to = c[(e + 1) % 4], step = glm::sign(to - from);
    const int axis = axes[step.x != 0 ? 0 : 1];
    loop.push_back(from);
    for (glm::ivec2 p = from + step; p != to; p += step)
      if (splitsEdge(corners, split, quadPoint(q, p.x, p.y), axis)) loop.push_back(p);
  }
  return loop;
}

// A rectangle one voxel thin along v: triangles zipped between the rails v = v0 and v = v1
// (`low` and `high`, ascending u), each with one side on a rail, so none is degenerate.
void zipRails(QuadEmitter& out, const std::vector<glm::ivec2>& low,
              const std::vector<glm::ivec2>& high, bool transposed) {
  auto tri = [&](glm::ivec2 a, glm::ivec2 b, glm::ivec2 c) {
    if (!transposed) return out.triangle(a, b, c);
    const auto t = [](glm::ivec2 p) { return glm::ivec2(p.y, p.x); };
    out.triangle(t(a), t(c), t(b));  // transposing mirrors the winding
  };
  size_t i = 0, j = 0;
  while (i + 1 < low.size() || j + 1 < high.size()) {
    if (j + 1 == high.size() || (i + 1 < low.size() && low[i + 1].x <= high[j + 1].x)) {
      tri(low[i], low[i + 1], high[j]);
      ++i;
    } else {
      tri(low[i], high[j + 1], high[j]);
      ++j;
    }
  }
}

void emitThin(QuadEmitter& out, const MeshQuad& q, const std::vector<glm::ivec2>& loop) {
  const bool transposed = q.u1 - q.u0 == 1 && q.v1 - q.v0 > 1;
  const auto t = [&](glm::ivec2 p) { return transposed ? glm::ivec2(p.y, p.x) : p; };
  const int v0 = transposed ? q.u0 : q.v0;
  std::vector<glm::ivec2> low, high;
  for (const glm::ivec2& p : loop) (t(p).y == v0 ? low : high).push_back(t(p));
  const auto by_u = [](glm::ivec2 a, glm::ivec2 b) { return a.x < b.x; };
  std::sort(low.begin(), low.end(), by_u);
  std::sort(high.begin(), high.end(), by_u);
  zipRails(out, low, high, transposed);
}

// An unsplit rectangle keeps its two triangles; a split one is fanned from an integer point
// strictly inside it (every fan triangle then has a side on the outline, so none is
// degenerate), or zipped when a one-voxel side leaves no such point.
void emitWatertight(BlockMesh& mesh, const MeshQuad& q, const CornerSet& corners,
                    const BoundarySplit& split) {
  QuadEmitter out(mesh, q);
  const std::vector<glm::ivec2> loop = boundaryLoop(q, corners, split);
  if (loop.size() == 4) {
    out.triangle(loop[0], loop[1], loop[2]);
    out.triangle(loop[0], loop[2], loop[3]);
  } else if (q.u1 - q.u0 >= 2 && q.v1 - q.v0 >= 2) {
    const glm::ivec2 inside((q.u0 + q.u1) / 2, (q.v0 + q.v1) / 2);
    for (size_t k = 0; k < loop.size(); ++k)
      out.triangle(inside, loop[k], loop[(k + 1) % loop.size()]);
  } else {
    emitThin(out, q, loop);
  }
}

}  // namespace

std::vector<MeshQuad> greedyQuads(const std::array<uint8_t, 4096>& voxels) {
  std::vector<MeshQuad> quads;
  for (int face = 0; face < 6; ++face) {
    for (int layer = 0; layer < kSize; ++layer) meshLayer(voxels, face, layer, quads);
  }
  return quads;
}

BlockMesh greedyMesh(const std::array<uint8_t, 4096>& voxels) {
  BlockMesh mesh;
  for (const MeshQuad& q : greedyQuads(voxels)) {
    QuadEmitter out(mesh, q);
    const glm::ivec2 c[4] = {{q.u0, q.v0}, {q.u1, q.v0}, {q.u1, q.v1}, {q.u0, q.v1}};
    out.triangle(c[0], c[1], c[2]);
    out.triangle(c[0], c[2], c[3]);
    ++mesh.quad_count;
  }
  return mesh;
}

BlockMesh watertightMesh(const std::vector<MeshQuad>& quads, const BoundarySplit& split) {
  const CornerSet corners(quads);
  BlockMesh mesh;
  for (const MeshQuad& q : quads) emitWatertight(mesh, q, corners, split);
  mesh.quad_count = int(quads.size());
  return mesh;
}

BlockMesh watertightMesh(const std::array<uint8_t, 4096>& voxels) {
  return watertightMesh(greedyQuads(voxels), [](const glm::ivec3&) { return true; });
}

std::vector<glm::ivec3> boundaryCorners(const std::vector<MeshQuad>& quads) {
  std::vector<glm::ivec3> out;
  for (const MeshQuad& q : quads)
    for (const glm::ivec2 uv : {glm::ivec2(q.u0, q.v0), glm::ivec2(q.u1, q.v0),
                                glm::ivec2(q.u1, q.v1), glm::ivec2(q.u0, q.v1)}) {
      const glm::ivec3 c = quadPoint(q, uv.x, uv.y);
      if (onBoundary(c.x) || onBoundary(c.y) || onBoundary(c.z)) out.push_back(c);
    }
  return out;
}

}  // namespace rdm::viewer
