// In-block reflections: before a sharp reflection falls back to the RDM, the ray walks the
// voxels near its start, where the RDM cannot see (its face origin lies on the block
// boundary, so voxels of the shaded block, and of a neighbour under a dead face origin, are
// behind or around it). A voxel hit is shaded with its own block's baked diffuse light, the
// shadow-mapped sun and emission; a ray that finds nothing nearby uses the RDM as before.
#ifndef VIEWER_NEAR_VOXELS_GLSL
#define VIEWER_NEAR_VOXELS_GLSL

#include "surface_light.glsl"

// Roughness levels whose specular walks the near voxels: a single ray stands for the lobe
// only when it is narrow (level 1: alpha = 0.02).
const int kNearMaxLevel = 1;
// Voxel steps per walk: a block's diagonal (3 x 16) plus the depth below.
const int kNearSteps = 64;
// How far (voxels) past the RDM's face plane the walk still looks before trusting the RDM.
// Faces without a usable RDM (skipped, or dead: the origin is inside a neighbour's voxel) walk
// the whole 3 x 3 x 3 slot neighbourhood instead.
const float kNearBeyondPlane = 4.0;

struct NearHit {
  bool hit;
  ivec3 voxel;  // world voxel coordinates (slot * 16 + local)
  int face;     // the face of `voxel` the ray entered through
  uint word;    // its material word
  vec3 point;   // entry point, world voxel coordinates
};

// First cell past the empty cube of `size` voxels at `lo` that the ray leaves at time t
// (exit axis `a`), and the boundary times of that cell; cells off the exit axis are clamped
// into the cube, since the exit point lies on its boundary.
void leaveCube(ivec3 lo, int size, vec3 o, vec3 d, ivec3 step, inout ivec3 cell,
               inout vec3 t_max, out float t, out int axis) {
  vec3 t_exit = vec3(1e30);
  for (int a = 0; a < 3; ++a) {
    if (step[a] == 0) continue;
    float boundary = float(lo[a] + (step[a] > 0 ? size : 0));
    t_exit[a] = (boundary - o[a]) / d[a];
  }
  axis = t_exit.x < t_exit.y ? (t_exit.x < t_exit.z ? 0 : 2) : (t_exit.y < t_exit.z ? 1 : 2);
  t = t_exit[axis];
  cell = clamp(ivec3(floor(o + t * d)), lo, lo + size - 1);
  cell[axis] = step[axis] > 0 ? lo[axis] + size : lo[axis] - 1;
  for (int a = 0; a < 3; ++a) {
    if (step[a] != 0) t_max[a] = (float(cell[a] + (step[a] > 0 ? 1 : 0)) - o[a]) / d[a];
  }
}

// Amanatides-Woo walk of o + t d (world voxel coordinates, o just in front of the surface)
// through the slots within one of `slot`; an empty slot, and an empty 4^3 brick of a block,
// is crossed in one step. Stops at the first solid voxel, after kNearSteps, or (when
// `bounded`) once the ray is kNearBeyondPlane voxels in front of face `face`'s plane.
NearHit nearVoxelWalk(ivec3 slot, int face, vec3 o, vec3 d, bool bounded) {
  NearHit h;
  h.hit = false;
  ivec3 cell = ivec3(floor(o));
  ivec3 step = ivec3(sign(d));
  vec3 t_max = vec3(1e30), t_delta = vec3(1e30);
  for (int a = 0; a < 3; ++a) {
    if (step[a] == 0) continue;
    t_delta[a] = abs(1.0 / d[a]);
    t_max[a] = (float(cell[a] + (step[a] > 0 ? 1 : 0)) - o[a]) / d[a];
  }
  vec3 n = vec3(faceNormal(face));
  float plane = dot(vec3(slot * kBlockSize + kBlockSize / 2), n) + float(kBlockSize / 2);
  ivec3 block_slot = ivec3(-1 << 20);
  int block = -1;
  uvec2 bricks = uvec2(0u);
  float t = 0.0;
  int a = 0;  // the axis of the last step
  for (int k = 0; k < kNearSteps; ++k) {
    ivec3 s = cell >> 4;  // arithmetic shift: floor division by kBlockSize
    if (any(greaterThan(abs(s - slot), ivec3(1))) || !slotInGrid(s)) return h;
    if (bounded && dot(o + t * d, n) - plane > kNearBeyondPlane) return h;
    if (s != block_slot) {
      block_slot = s;
      block = slots[slotIndex(s)].header.x;
      if (block >= 0) bricks = blockBricks(block);
    }
    if (block < 0) {
      leaveCube(s * kBlockSize, kBlockSize, o, d, step, cell, t_max, t, a);
      continue;
    }
    ivec3 l = cell - s * kBlockSize;
    int brick = (l.x >> 2) | (l.y >> 2) << 2 | (l.z >> 2) << 4;
    if (((brick < 32 ? bricks.x : bricks.y) >> (brick & 31) & 1u) == 0u) {
      leaveCube(cell & ~3, 4, o, d, step, cell, t_max, t, a);
      continue;
    }
    uint word = blockVoxel(block, l);
    if (k > 0 && materialSolid(word >> 24)) {  // the start cell is in front of the surface
      h.hit = true;
      h.voxel = cell;
      h.face = 2 * a + (step[a] > 0 ? 1 : 0);  // entered against the step: normal -step
      h.word = word;
      h.point = o + t * d;
      return h;
    }
    a = t_max.x < t_max.y ? (t_max.x < t_max.z ? 0 : 2) : (t_max.y < t_max.z ? 1 : 2);
    t = t_max[a];
    cell[a] += step[a];
    t_max[a] += t_delta[a];
  }
  return h;
}

// Light leaving the hit towards the walk's start; its own specular from its RDM, without the
// march (a second bounce: docs/results.md section 1b measured the march's change as 4e-6 FLIP).
vec3 nearHitRadiance(NearHit h, vec3 d) {
  SurfaceMaterial s = decodeVoxel(h.word);
  ivec3 slot = h.voxel >> 4;
  vec3 n = vec3(faceNormal(h.face));
  vec3 p = h.point / float(kBlockSize);
  vec3 p01 = p - vec3(slot);
  vec3 v = -d;
  vec3 lr = termOn(kTermSpecular) ? rdmSpecularDistant(slot, h.face, s.level, reflect(d, n))
                                  : vec3(0.0);
  return surfaceRadiance(s, slot, h.face, p01, p, n, v, lr);
}

// Specular radiance along r from world point p on face `face` of `slot` (roughness `level`):
// the near voxels first when the term is on and the lobe is sharp, else (and on no hit)
// rdmSpecular.
vec3 specularRadiance(ivec3 slot, int face, int level, vec3 p, vec3 r) {
  if (termOn(kTermInBlock) && level <= kNearMaxLevel) {
    ivec4 header = slots[slotIndex(slot)].header;
    bool usable = ((header.y & ~header.z) & (1 << face)) != 0;
    vec3 n = vec3(faceNormal(face));
    NearHit h = nearVoxelWalk(slot, face, p * float(kBlockSize) + n * 1e-3, r, usable);
    if (h.hit) return nearHitRadiance(h, r);
  }
  return rdmSpecular(slot, face, level, p, r);
}

#endif  // VIEWER_NEAR_VOXELS_GLSL
