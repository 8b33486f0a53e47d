// Reflections through the voxels (docs/spec.md section 6): before a reflection falls back to
// the RDM, the reflected ray walks the voxel grid the viewer holds. The RDM sees the world
// from its face origin, so whatever lies close to the shaded point, or in front of the origin
// at another angle than from the point, lands at the wrong place in it (thesis Fig. 3.9); the
// walk sees it from the point. A voxel hit is shaded with its own stored light (face light or
// RDM diffuse, its own specular from its RDM, the shadow-mapped sun, emission).
//   Far walk (levels 0 and 1: mirrors and polished surfaces, whose lobe one ray stands for):
//   the whole ray through the grid, up to kWalkSteps steps; a ray that leaves the grid sees
//   the sky, one that runs out of steps marches the RDM from where it stopped.
//   Near walk (levels 2 and 3): the 3 x 3 x 3 slots around the point, and only kNearBeyondPlane
//   voxels past the RDM's face plane, where the RDM cannot see (behind its origin); farther
//   away the prefiltered RDM stands for the wider lobe better than one ray.
#ifndef VIEWER_NEAR_VOXELS_GLSL
#define VIEWER_NEAR_VOXELS_GLSL

#include "rdm_walk.h"
#include "surface_light.glsl"

// The roughness levels of the far walk (level 1: alpha = 0.02) and of any walk (level 3:
// alpha = 0.18); measured in docs/results.md section 1g.
const int kFarMaxLevel = 1;
const int kNearMaxLevel = 3;
// Steps of a walk (an empty slot, an empty brick or a voxel each): a near walk needs a block's
// diagonal (3 x 16) plus the depth below; island's and chess's far walks all end within 48
// (docs/results.md section 1g). A far walk that runs out marches the RDM from there.
const int kWalkSteps = 64;
// How far (voxels) past the RDM's face plane a near walk still looks before trusting the RDM.
// Faces without a usable RDM (skipped, or dead: the origin is inside a neighbour's voxel) walk
// the whole 3 x 3 x 3 slot neighbourhood instead.
const float kNearBeyondPlane = 4.0;
const float kUnbounded = 1e30;
// Walks a far reflection takes, following the mirrors and polished surfaces it hits (a
// corridor's facing mirrors show each other's images 3 deep).
const int kFarBounces = 3;

struct NearHit {
  bool hit;
  ivec3 voxel;  // world voxel coordinates (slot * 16 + local)
  int face;     // the face of `voxel` the ray entered through
  uint word;    // its material word
  vec3 point;   // entry point, world voxel coordinates
  float t;      // the ray length (voxels) walked: at the hit, or where the walk gave up
  bool escaped; // no hit: the ray left the grid (nothing but sky beyond)
};

// How far a walk goes: slots within `slot_radius` of the start's, and (voxels)
// `beyond_plane` past the RDM's face plane.
struct NearBounds {
  int slot_radius;
  float beyond_plane;
};

NearBounds nearBounds(int level, bool usable) {
  if (level <= kFarMaxLevel) return NearBounds(1 << 16, kUnbounded);
  return NearBounds(1, usable ? kNearBeyondPlane : kUnbounded);
}

// The voxel walk of docs/spec.md section 5 (shared/rdm_walk.h, as the bake kernel walks) of
// o + t d (world voxel coordinates, o just in front of the surface) from face `face` of
// `slot`, within `bounds`; an empty slot, and (regular rays) an empty 4^3 brick of a block, is
// crossed in one step. Stops at the first solid voxel, after kWalkSteps, or out of bounds.
NearHit nearVoxelWalk(ivec3 slot, int face, vec3 o, vec3 d, NearBounds bounds) {
  NearHit h;
  h.hit = false;
  h.escaped = false;
  h.t = 0.0;
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
  for (int k = 0; k < kWalkSteps; ++k) {
    h.t = w.t;
    ivec3 s = w.cell >> 4;  // arithmetic shift: floor division by kBlockSize
    if (any(greaterThan(abs(s - slot), ivec3(bounds.slot_radius)))) return h;
    if (dot(o + w.t * d, n) - plane > bounds.beyond_plane) return h;
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
    h.escaped = any(lessThan(w.cell, ivec3(0))) || any(greaterThanEqual(w.cell, extent));
    if (w.mask == 0 || h.escaped) return h;
  }
  return h;
}

// The hit's RDM face, its material, and the normal, point (world units) and view vector there.
struct HitSurface {
  ivec3 slot;
  int face;
  SurfaceMaterial s;
  vec3 n, p, v;
};

HitSurface hitSurface(NearHit h, vec3 d) {
  HitSurface x;
  x.slot = h.voxel >> 4;
  x.face = h.face;
  x.s = decodeVoxel(h.word);
  x.n = vec3(faceNormal(h.face));
  x.p = h.point / float(kBlockSize);
  x.v = -d;
  return x;
}

// Light leaving the hit towards the walk's start, with indirect specular `lr`.
vec3 hitRadiance(HitSurface x, vec3 lr) {
  return surfaceRadiance(x.s, x.slot, x.face, x.p - vec3(x.slot), x.p, x.n, x.v, lr);
}

// Specular radiance along r from world point p on face `face` of `slot` (roughness `level`):
// the voxel walk first when the term is on and the lobe is narrow enough, else (and on a
// miss) rdmSpecular. A far walk's hit on another surface of a far level is followed, up to
// kFarBounces walks (facing mirrors show each other), each adding the surface's own light
// weighted by the specular weights before it. The last hit takes its own specular from its
// RDM without the march (a second bounce: docs/results.md section 1b measured the march's
// change as 4e-6 FLIP). Each function is called once here: lavapipe inlines every call, and
// a second walk or march in the shader slowed even the flat frame 2x.
vec3 specularRadiance(ivec3 slot, int face, int level, vec3 p, vec3 r) {
  vec3 sum = vec3(0.0), weight = vec3(1.0);
  float t_start = 0.0;
  if (termOn(kTermInBlock) && level <= kNearMaxLevel) {
    bool far = level <= kFarMaxLevel;
    bool usable = faceUsable(slots[slotIndex(slot)].header, face);
    vec3 o = p * float(kBlockSize) + vec3(faceNormal(face)) * 1e-3;
    for (int walk = 1; walk <= kFarBounces; ++walk) {
      NearHit h = nearVoxelWalk(slot, face, o, r, nearBounds(level, usable));
      if (!h.hit) {
        if (far && h.escaped) return sum + weight * skyRadiance(r);  // no sun disc, as an RDM
        if (far) t_start = h.t / float(kBlockSize);
        break;
      }
      HitSurface x = hitSurface(h, r);
      bool follow = far && walk < kFarBounces && x.s.level <= kFarMaxLevel && termOn(kTermSpecular);
      vec3 lr = !follow && termOn(kTermSpecular)
                    ? rdmSpecularDistant(x.slot, x.face, x.s.level, reflect(r, x.n))
                    : vec3(0.0);
      sum += weight * hitRadiance(x, lr);
      if (!follow) return sum;
      weight *= specularWeight(x.s, dfgLookup(x.s.level, max(dot(x.n, x.v), 1e-4)));
      slot = x.slot, face = x.face, level = x.s.level, p = x.p, r = reflect(r, x.n);
      o = h.point + x.n * 1e-3;
    }
  }
  return sum + weight * blendedRdmSpecular(slot, face, level, p, r, t_start);
}

#endif  // VIEWER_NEAR_VOXELS_GLSL
