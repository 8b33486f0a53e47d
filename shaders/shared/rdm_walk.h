// The float voxel walk of docs/spec.md section 5, one step at a time: what rdm::referenceWalk
// does for a FloatRay, written once for the C++ core, the Vulkan bake kernel and the viewer's
// in-block reflections. Every time is the boundary time of an integer plane, never
// accumulated; axes reaching a boundary at the same time step together. A program supplies
// the world (which slots and 4^3 bricks are empty, which voxels are solid) and calls one
// step, walkLeave, with the size of the empty cube around the cell (walkStepBits). No
// function has a loop: lavapipe counts every back-edge against an invocation's budget
// (section 9).
#ifndef RDM_WALK_H
#define RDM_WALK_H

#ifdef __cplusplus
#include "rdm_shared.h"
namespace rdm::shared {
#define RDM_FN inline
#define RDM_CONST constexpr
#define RDM_INOUT(T) T&
#else
#include "rdm_shared.h"
#define RDM_FN
#define RDM_CONST const
#define RDM_INOUT(T) inout T
#endif

// ---- One axis of a ray o + t d (inv = 1 / d) ----------------------------------------------
RDM_FN float walkBoundaryTime(float o, float inv, int plane) { return (float(plane) - o) * inv; }
// The start cell: a point on a boundary belongs to the cell being entered; a still axis
// (d = +-0) keeps floor(o).
RDM_FN int walkStartCell(float o, float d) {
  return (d == 0.0f || d > 0.0f) ? int(floor(o)) : int(ceil(o)) - 1;
}
// One fix-up of walkCellAt: moves c by a cell when the boundary times say the ray has not
// reached, or has passed, it at time t.
RDM_FN int walkCellFix(float o, float d, float inv, float t, int c, int lo, int hi) {
  if (d > 0.0f) {
    if (c < hi && walkBoundaryTime(o, inv, c + 1) <= t) return c + 1;
    if (c > lo && walkBoundaryTime(o, inv, c) > t) return c - 1;
  } else {
    if (c > lo && walkBoundaryTime(o, inv, c) <= t) return c - 1;
    if (c < hi && walkBoundaryTime(o, inv, c + 1) > t) return c + 1;
  }
  return c;
}
// The cell of a non-crossing moving axis at time t, consistent with the boundary-time ties,
// clamped to [lo, hi]. floor(o + t d) is at most one cell off in a grid of at most 4096 voxels
// (its rounding error is far below a voxel), so two fix-ups settle it.
RDM_FN int walkCellAt(float o, float d, float inv, float t, int lo, int hi) {
  float p = o + t * d;
  int c = clamp(d > 0.0f ? int(floor(p)) : int(ceil(p)) - 1, lo, hi);
  c = walkCellFix(o, d, inv, t, c, lo, hi);
  return walkCellFix(o, d, inv, t, c, lo, hi);
}

// ---- The walk's state ----------------------------------------------------------------------
struct ShWalk {
  vec3 o, d, inv;
  ivec3 cell;
  float t;   // the time `cell` was entered
  int mask;  // axes crossed to enter `cell` (entryAxis decides the hit normal); 0 at the start
};
RDM_FN bool walkMoving(ShWalk w, int a) { return w.d[a] != 0.0f; }
RDM_FN bool walkPositive(ShWalk w, int a) { return w.d[a] > 0.0f; }
RDM_FN float walkTime(ShWalk w, int a, int plane) {
  return walkBoundaryTime(w.o[a], w.inv[a], plane);
}
// FloatRay::regular: |o| <= 2^20 and 1e-20 <= |1/d| <= 1e20 on moving axes, and some axis
// moves. Then every boundary time is finite and strictly increasing along the ray, which a
// brick step needs to land where voxel steps would.
RDM_FN bool walkAxisRegular(ShWalk w, int a) {
  return abs(w.o[a]) <= 1048576.0f &&
         (!walkMoving(w, a) || (abs(w.inv[a]) <= 1e20f && abs(w.inv[a]) >= 1e-20f));
}
RDM_FN bool walkRegular(ShWalk w) {
  return walkAxisRegular(w, 0) && walkAxisRegular(w, 1) && walkAxisRegular(w, 2) &&
         (walkMoving(w, 0) || walkMoving(w, 1) || walkMoving(w, 2));
}

// ---- Entering the grid [0, extent) -----------------------------------------------------------
// The entry of one axis: the latest near-plane time (with its tie mask) and the earliest far
// one; false when a still axis lies outside the grid.
RDM_FN bool walkEnterAxis(ShWalk w, int a, ivec3 extent, RDM_INOUT(float) t_enter,
                          RDM_INOUT(float) t_exit, RDM_INOUT(bool) entering,
                          RDM_INOUT(bool) has_exit, RDM_INOUT(int) mask) {
  if (!walkMoving(w, a)) {
    int c = walkStartCell(w.o[a], w.d[a]);
    return c >= 0 && c < extent[a];
  }
  float t_near = walkTime(w, a, walkPositive(w, a) ? 0 : extent[a]);
  float t_far = walkTime(w, a, walkPositive(w, a) ? extent[a] : 0);
  if (t_enter < t_near) {
    t_enter = t_near;
    mask = 1 << a;
    entering = true;
  } else if (entering && t_enter == t_near) {
    mask |= 1 << a;
  }
  if (!has_exit || t_far < t_exit) {
    t_exit = t_far;
    has_exit = true;
  }
  return true;
}
RDM_FN bool walkEnterCell(RDM_INOUT(ShWalk) w, int a, ivec3 extent, bool entering) {
  if ((w.mask & (1 << a)) != 0) {
    w.cell[a] = walkPositive(w, a) ? 0 : extent[a] - 1;
  } else if (entering && walkMoving(w, a)) {
    w.cell[a] = walkCellAt(w.o[a], w.d[a], w.inv[a], w.t, 0, extent[a] - 1);
  } else {
    w.cell[a] = walkStartCell(w.o[a], w.d[a]);
    if (w.cell[a] < 0 || w.cell[a] >= extent[a]) return false;
  }
  return true;
}
// Starts the walk of o + t d, t >= 0, in the grid [0, extent); false when the ray misses it.
RDM_FN bool walkStart(RDM_INOUT(ShWalk) w, vec3 o, vec3 d, ivec3 extent) {
  w.o = o;
  w.d = d;
  w.inv = vec3(1.0f) / d;
  float t_enter = 0.0f, t_exit = 0.0f;
  bool entering = false, has_exit = false;
  int mask = 0;
  if (!walkEnterAxis(w, 0, extent, t_enter, t_exit, entering, has_exit, mask)) return false;
  if (!walkEnterAxis(w, 1, extent, t_enter, t_exit, entering, has_exit, mask)) return false;
  if (!walkEnterAxis(w, 2, extent, t_enter, t_exit, entering, has_exit, mask)) return false;
  if (has_exit && !(t_enter < t_exit)) return false;
  w.t = t_enter;
  w.mask = mask;
  bool inside = walkEnterCell(w, 0, extent, entering) && walkEnterCell(w, 1, extent, entering) &&
                walkEnterCell(w, 2, extent, entering);
  return inside;
}

// walkStart for an origin inside the grid (0 <= o < extent on every axis), without the entry
// times: the start cell holds o, t = 0 and no axis was crossed. The same state walkStart gives.
RDM_FN void walkStartInside(RDM_INOUT(ShWalk) w, vec3 o, vec3 d) {
  w.o = o;
  w.d = d;
  w.inv = vec3(1.0f) / d;
  w.t = 0.0f;
  w.mask = 0;
  w.cell = ivec3(walkStartCell(o.x, d.x), walkStartCell(o.y, d.y), walkStartCell(o.z, d.z));
}

// ---- Steps ---------------------------------------------------------------------------------
// The earliest of the moving axes' times: sets w.t, returns the mask of the axes reaching it
// (the first moving axis seeds the minimum, so even a degenerate ray's NaN time is ordered as
// referenceWalk orders it).
RDM_FN void walkEarliestAxis(RDM_INOUT(ShWalk) w, int a, float t, RDM_INOUT(int) mask) {
  if (!walkMoving(w, a)) return;
  if (mask == 0 || t < w.t) {
    w.t = t;
    mask = 1 << a;
  } else if (t == w.t) {
    mask |= 1 << a;
  }
}
RDM_FN int walkEarliest(RDM_INOUT(ShWalk) w, vec3 times) {
  int mask = 0;
  walkEarliestAxis(w, 0, times.x, mask);
  walkEarliestAxis(w, 1, times.y, mask);
  walkEarliestAxis(w, 2, times.z, mask);
  return mask;
}
// The earliest time at which a moving axis reaches its plane in `planes`.
RDM_FN int walkNextCrossing(RDM_INOUT(ShWalk) w, ivec3 planes) {
  return walkEarliest(w, vec3(walkTime(w, 0, planes.x), walkTime(w, 1, planes.y),
                              walkTime(w, 2, planes.z)));
}
RDM_FN ivec3 walkPositiveAxes(ShWalk w) { return ivec3(greaterThan(w.d, vec3(0.0f))); }

// The sizes of cube a step leaves (log2 of the side, in voxels).
RDM_CONST int kWalkVoxelBits = 0;
RDM_CONST int kWalkBrickBits = 2;   // an empty 4^3 brick of a block
RDM_CONST int kWalkOctantBits = 3;  // an empty 8^3 octant of a block
RDM_CONST int kWalkSlotBits = 4;    // an empty slot
// The cube the walk may leave in one step: an empty slot; an empty brick of a block for a
// walkRegular ray (its boundary times strictly increase, so the step lands where voxel steps
// would); else the voxel.
RDM_FN int walkStepBits(bool slot_empty, bool brick_empty, bool regular) {
  return slot_empty ? kWalkSlotBits : (brick_empty && regular ? kWalkBrickBits : kWalkVoxelBits);
}
// The 8 bits of the 8^3 octant holding brick `brick` (walkBrickIndex) in the 32-bit half of
// its block's brick mask that holds the brick's own bit (bit brick >> 5 of the half's index).
RDM_FN uint walkOctantMask(int brick) {
  return 0x00330033u << uint((brick & 2) + ((brick >> 3) & 1) * 8);
}
// The cube a regular ray may leave in one step from a cell of a block, given the half `word`
// of the block's brick mask that holds the cell's brick: an empty octant, an empty brick, or
// (the brick has a solid voxel, or the ray is not walkRegular) the voxel.
RDM_FN int walkBlockStepBits(uint word, int brick, bool regular) {
  if (!regular || ((word >> uint(brick & 31)) & 1u) != 0u) return kWalkVoxelBits;
  return (word & walkOctantMask(brick)) == 0u ? kWalkOctantBits : kWalkBrickBits;
}
// One axis of walkLeave: an exit axis steps out of the cube [lo, lo + 2^bits); any other
// moving axis moves to its cell at the exit time w.t, inside the cube (walkCellAt), and in a
// brick or an octant joins the mask if it crosses a voxel plane exactly then, as voxel steps
// would.
RDM_FN void walkLeaveAxis(RDM_INOUT(ShWalk) w, int a, int bits, int exit_mask,
                          RDM_INOUT(int) mask) {
  int lo = (w.cell[a] >> bits) << bits;
  int hi = lo + (1 << bits) - 1;
  if ((exit_mask & (1 << a)) != 0) {
    w.cell[a] = walkPositive(w, a) ? hi + 1 : lo - 1;
  } else if (walkMoving(w, a)) {
    int c = walkCellAt(w.o[a], w.d[a], w.inv[a], w.t, lo, hi);
    if (bits != kWalkSlotBits && c != w.cell[a] &&
        walkTime(w, a, walkPositive(w, a) ? c : c + 1) == w.t)
      mask |= 1 << a;
    w.cell[a] = c;
  }
}
// The step: leaves the cube of side 2^bits (walkStepBits) holding the cell. The axes reaching
// its exit planes first cross them together. A voxel step moves only those; a slot step's
// mask holds only them, as referenceWalk's does. One call for every kind of cell, so
// invocations in different kinds run the same code (on lavapipe the three divergent steps
// cost the viewer's in-block walk and the bake kernel more: docs/performance.md).
RDM_FN void walkLeave(RDM_INOUT(ShWalk) w, int bits) {
  ivec3 planes = ((w.cell >> bits) + walkPositiveAxes(w)) << bits;
  int exit_mask = walkNextCrossing(w, planes);
  int mask = exit_mask;
  walkLeaveAxis(w, 0, bits, exit_mask, mask);
  walkLeaveAxis(w, 1, bits, exit_mask, mask);
  walkLeaveAxis(w, 2, bits, exit_mask, mask);
  w.mask = mask;
}
// The 4^3 brick of a block-local cell: bit (x >> 2) | (y >> 2) << 2 | (z >> 2) << 4 of a
// block's occupancy mask.
RDM_FN int walkBrickIndex(ivec3 local) {
  return (local.x >> 2) | (local.y >> 2) << 2 | (local.z >> 2) << 4;
}

#ifdef __cplusplus
}  // namespace rdm::shared
#endif
#undef RDM_FN
#undef RDM_CONST
#undef RDM_INOUT
#endif  // RDM_WALK_H
