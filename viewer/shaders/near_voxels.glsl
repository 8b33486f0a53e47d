// In-block reflections: before a sharp reflection falls back to the RDM, the ray walks the
// voxels near its start, where the RDM cannot see (its face origin lies on the block
// boundary, so voxels of the shaded block, and of a neighbour under a dead face origin, are
// behind or around it). A voxel hit is shaded with its own block's baked diffuse light, the
// shadow-mapped sun and emission; a ray that finds nothing nearby uses the RDM as before.
#ifndef VIEWER_NEAR_VOXELS_GLSL
#define VIEWER_NEAR_VOXELS_GLSL

#include "rdm_walk.h"
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

// The voxel walk of docs/spec.md section 5 (shared/rdm_walk.h, as the bake kernel walks) of
// o + t d (world voxel coordinates, o just in front of the surface) through the slots within
// one of `slot`; an empty slot, and (regular rays) an empty 4^3 brick of a block, is crossed in
// one step. Stops at the first solid voxel, after kNearSteps, or (when `bounded`) once the
// ray is kNearBeyondPlane voxels in front of face `face`'s plane.
NearHit nearVoxelWalk(ivec3 slot, int face, vec3 o, vec3 d, bool bounded) {
  NearHit h;
  h.hit = false;
  ShWalk w;
  ivec3 extent = frame.grid_size.xyz * kBlockSize;
  if (any(lessThan(o, vec3(0.0))) || any(greaterThanEqual(o, vec3(extent)))) return h;
  walkStartInside(w, o, d);
  bool regular = walkRegular(w);
  vec3 n = vec3(faceNormal(face));
  float plane = dot(vec3(slot * kBlockSize + kBlockSize / 2), n) + float(kBlockSize / 2);
  ivec3 block_slot = ivec3(-1 << 20);
  int block = -1;
  uvec2 bricks = uvec2(0u);
  for (int k = 0; k < kNearSteps; ++k) {
    ivec3 s = w.cell >> 4;  // arithmetic shift: floor division by kBlockSize
    if (any(greaterThan(abs(s - slot), ivec3(1)))) return h;
    if (bounded && dot(o + w.t * d, n) - plane > kNearBeyondPlane) return h;
    if (s != block_slot) {
      block_slot = s;
      block = slots[slotIndex(s)].header.x;
      if (block >= 0) bricks = blockBricks(block);
    }
    ivec3 l = w.cell - s * kBlockSize;
    int brick = walkBrickIndex(l);
    bool slot_empty = block < 0;
    bool brick_empty =
        !slot_empty && ((brick < 32 ? bricks.x : bricks.y) >> (brick & 31) & 1u) == 0u;
    if (!slot_empty && !brick_empty) {
      uint word = blockVoxel(block, l);
      if (k > 0 && materialSolid(word >> 24)) {  // the start cell is in front of the surface
        int axis = entryAxis(w.mask, w.d);
        h.hit = true;
        h.voxel = w.cell;
        h.face = entryFace(axis, w.d[axis]);
        h.word = word;
        h.point = entryPoint(o, d, w.t, w.cell, axis);
        return h;
      }
    }
    walkLeave(w, walkStepBits(slot_empty, brick_empty, regular));
    if (w.mask == 0 || any(lessThan(w.cell, ivec3(0))) || any(greaterThanEqual(w.cell, extent)))
      return h;
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
