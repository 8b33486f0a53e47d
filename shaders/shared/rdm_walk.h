// The float voxel walk of docs/spec.md section 5, one step at a time: what rdm::referenceWalk
// does for a FloatRay, written once for the C++ core (FloatRay's per-axis rules, and the
// tests that hold it to referenceWalk) and the Vulkan bake kernel. Every time is the boundary time of an integer plane, never
// accumulated; axes reaching a boundary at the same time step together. A program supplies
// the world (which slots and 4^3 bricks are empty, which voxels are solid) and calls the
// step that fits the cell: walkVoxelStep, walkBrickStep or walkSlotStep. No function has a
// loop: lavapipe counts every back-edge against an invocation's budget (section 9).
#ifndef RDM_WALK_H
#define RDM_WALK_H

#ifdef __cplusplus
#include <limits>

#include "rdm_shared.h"
namespace rdm::shared {
#define RDM_FN inline
#define RDM_INOUT(T) T&
#else
#include "rdm_shared.h"
#define RDM_FN
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
  vec3 tn;   // per axis, the time the ray leaves `cell` (+inf on a still axis): a cache of
             // boundary times, which walkExitTimes recomputes from the rest
};
RDM_FN bool walkMoving(ShWalk w, int a) { return w.d[a] != 0.0f; }
RDM_FN bool walkPositive(ShWalk w, int a) { return w.d[a] > 0.0f; }
RDM_FN float walkTime(ShWalk w, int a, int plane) {
  return walkBoundaryTime(w.o[a], w.inv[a], plane);
}
RDM_FN float walkExitTime(ShWalk w, int a) {
  return walkMoving(w, a) ? walkTime(w, a, w.cell[a] + (walkPositive(w, a) ? 1 : 0))
                          : uintBitsToFloat(0x7f800000u);  // +inf: a still axis never crosses
}
// Fills w.tn from the rest of the state (after a start, an empty slot or a resume).
RDM_FN void walkExitTimes(RDM_INOUT(ShWalk) w) {
  w.tn = vec3(walkExitTime(w, 0), walkExitTime(w, 1), walkExitTime(w, 2));
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
  walkExitTimes(w);
  return inside;
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
// One voxel: every axis reaching the earliest exit time steps.
RDM_FN void walkVoxelAxis(RDM_INOUT(ShWalk) w, int a) {
  if ((w.mask & (1 << a)) == 0) return;
  int off = walkPositive(w, a) ? 1 : 0;
  w.cell[a] += off != 0 ? 1 : -1;
  w.tn[a] = walkTime(w, a, w.cell[a] + off);
}
RDM_FN void walkVoxelStep(RDM_INOUT(ShWalk) w) {
  w.mask = walkEarliest(w, w.tn);
  walkVoxelAxis(w, 0);
  walkVoxelAxis(w, 1);
  walkVoxelAxis(w, 2);
}
// An empty slot (16^3 voxels) in one step: the axes crossing its planes first step out of it;
// the others move to their cell at that time, inside the slot.
RDM_FN void walkSlotAxis(RDM_INOUT(ShWalk) w, int a, ivec3 slot, ivec3 planes) {
  if ((w.mask & (1 << a)) != 0) {
    w.cell[a] = walkPositive(w, a) ? planes[a] : planes[a] - 1;
  } else if (walkMoving(w, a)) {
    w.cell[a] = walkCellAt(w.o[a], w.d[a], w.inv[a], w.t, slot[a] * kBlockSize,
                           slot[a] * kBlockSize + kBlockSize - 1);
  }
}
RDM_FN void walkSlotStep(RDM_INOUT(ShWalk) w) {
  ivec3 slot = w.cell >> 4;
  ivec3 planes = (slot + walkPositiveAxes(w)) * kBlockSize;
  w.mask = walkNextCrossing(w, planes);
  walkSlotAxis(w, 0, slot, planes);
  walkSlotAxis(w, 1, slot, planes);
  walkSlotAxis(w, 2, slot, planes);
  walkExitTimes(w);
}
// An empty 4^3 brick of a block in one step, landing where voxel steps would (walkRegular
// rays only): the axes reaching the brick's exit time first cross it; every other moving
// axis catches up by voxel steps (at most 3) to its cell at that time and joins the mask if
// it crosses a voxel plane exactly then.
RDM_FN float walkBrickExitTime(ShWalk w, int a) {
  return walkMoving(w, a) ? walkTime(w, a, (w.cell[a] & ~3) + (walkPositive(w, a) ? 4 : 0))
                          : uintBitsToFloat(0x7f800000u);  // +inf: a still axis never crosses
}
RDM_FN void walkCatchUpStep(RDM_INOUT(ShWalk) w, int a, float t_exit, RDM_INOUT(bool) done,
                            RDM_INOUT(int) mask) {
  if (done || t_exit < w.tn[a]) {
    done = true;
    return;
  }
  if (t_exit == w.tn[a]) mask |= 1 << a;
  int off = walkPositive(w, a) ? 1 : 0;
  w.cell[a] += off != 0 ? 1 : -1;
  w.tn[a] = walkTime(w, a, w.cell[a] + off);
}
RDM_FN void walkBrickAxis(RDM_INOUT(ShWalk) w, int a, int exit_mask, float t_exit,
                          RDM_INOUT(int) mask) {
  if ((exit_mask & (1 << a)) != 0) {
    w.cell[a] = (w.cell[a] & ~3) + (walkPositive(w, a) ? 4 : -1);
    w.tn[a] = walkExitTime(w, a);
    return;
  }
  if (!walkMoving(w, a)) return;
  bool done = false;
  walkCatchUpStep(w, a, t_exit, done, mask);
  walkCatchUpStep(w, a, t_exit, done, mask);
  walkCatchUpStep(w, a, t_exit, done, mask);
}
RDM_FN void walkBrickStep(RDM_INOUT(ShWalk) w) {
  vec3 tb = vec3(walkBrickExitTime(w, 0), walkBrickExitTime(w, 1), walkBrickExitTime(w, 2));
  float t_exit = min(min(tb.x, tb.y), tb.z);
  int exit_mask = int(tb.x == t_exit) | int(tb.y == t_exit) << 1 | int(tb.z == t_exit) << 2;
  int mask = exit_mask;
  walkBrickAxis(w, 0, exit_mask, t_exit, mask);
  walkBrickAxis(w, 1, exit_mask, t_exit, mask);
  walkBrickAxis(w, 2, exit_mask, t_exit, mask);
  w.t = t_exit;
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
#undef RDM_INOUT
#endif  // RDM_WALK_H
