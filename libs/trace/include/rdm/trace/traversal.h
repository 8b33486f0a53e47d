// DDA through the voxel world (docs/spec.md section 5), in world voxel units. referenceWalk is the
// plain two-level walk and defines the result; traceVoxels gives the same result, bit for
// bit, with empty space crossed in larger steps.
// Boundary rule: on an axis with d != 0 a point on a boundary belongs to the cell being
// entered; on an axis with d == +-0 the cell is floor(p) and never changes. Axes that
// reach a boundary at the same t step together, so cells touched only along an edge or a
// corner are not entered. Every loop is bounded by the grid's extent.
//
// The walk is generic over the ray's time type: FloatRay for paths (float, per-axis
// boundary times computed from the integer plane, never accumulated) and ExactRay for texel
// central rays (integer origin and direction, times compared by cross-multiplication).
// Acceleration: empty slots and empty 4^3 bricks (VoxelWorld::occupancy) are crossed in one
// step each; float rays take the SSE2 walk of rdm/trace/float_walk.h (also one step per empty
// 2 x 2 x 2 group of slots). docs/performance.md has the measurements.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include <glm/glm.hpp>

#include "rdm/base/check.h"
#include "rdm/scene/world.h"
#include "rdm/transport/rdm_shared_cpp.h"

// The walk's steps inline into the loop: a call per step costs more than the step.
#define RDM_WALK_INLINE [[gnu::always_inline]] inline

namespace rdm {

struct TraceHit {
  bool hit = false;
  bool started_solid = false;  // the start cell was solid: the hit is at t = 0
  glm::ivec3 voxel{0};         // global voxel coordinates of the hit
  int axis = -1;               // axis crossed to enter the hit voxel, -1 if started solid
  uint8_t palette = 0;
  int steps = 0;
};

struct FloatRay {
  using Time = float;
  glm::vec3 o, d, inv;
  FloatRay(const glm::vec3& origin, const glm::vec3& dir) : o(origin), d(dir) {
    for (int a = 0; a < 3; ++a) inv[a] = 1.0f / dir[a];
  }
  bool moving(int a) const { return d[a] != 0.0f; }
  bool positive(int a) const { return d[a] > 0.0f; }
  Time zero() const { return 0.0f; }
  // Later than every boundary time of a regular ray: the time of an axis that never crosses.
  static Time never() { return std::numeric_limits<float>::infinity(); }
  // Regular: some axis moves, |o| <= 2^20 and 1e-20 <= |1/d| <= 1e20 on moving axes (NaN
  // fails). Then every boundary time of a grid plane is finite and strictly increasing along
  // the ray, so never() cannot tie with a crossing and skipping a brick lands where voxel
  // steps would. Other rays take referenceWalk.
  bool regular() const {
    bool any = false;
    for (int a = 0; a < 3; ++a) {
      if (!(std::abs(o[a]) <= 1048576.0f)) return false;
      if (!moving(a)) continue;
      if (!(std::abs(inv[a]) <= 1e20f && std::abs(inv[a]) >= 1e-20f)) return false;
      any = true;
    }
    return any;
  }
  // The earliest of three times (never() for still axes) and the mask of the axes reaching it.
  static int earliest(const Time* t, Time& t_min) {
    t_min = std::min(std::min(t[0], t[1]), t[2]);
    return int(t[0] == t_min) | int(t[1] == t_min) << 1 | int(t[2] == t_min) << 2;
  }
  // The per-axis rules are shaders/shared/rdm_walk.h's, which the Vulkan kernel and the
  // viewer walk with.
  Time boundaryTime(int a, int plane) const {
    return shared::walkBoundaryTime(o[a], inv[a], plane);
  }
  static bool less(Time x, Time y) { return x < y; }
  static bool equal(Time x, Time y) { return x == y; }
  int startCell(int a) const { return shared::walkStartCell(o[a], d[a]); }
  // Cell on a non-crossing axis at time t, consistent with the boundary-time ties of the
  // voxel walk, clamped to [lo, hi].
  int cellAt(int a, Time t, int lo, int hi) const {
    return shared::walkCellAt(o[a], d[a], inv[a], t, lo, hi);
  }
};

// Exact ray: integer origin (on voxel corners) and integer direction; t = num / den.
struct ExactRay {
  struct Time {
    int64_t num = 0, den = 1;  // den > 0
  };
  glm::ivec3 o, d;
  ExactRay(const glm::ivec3& origin, const glm::ivec3& dir) : o(origin), d(dir) {}
  bool moving(int a) const { return d[a] != 0; }
  bool positive(int a) const { return d[a] > 0; }
  Time zero() const { return {0, 1}; }
  static Time never() { return {1, 0}; }  // compares later than every finite time
  bool regular() const { return d != glm::ivec3(0); }
  static int earliest(const Time* t, Time& t_min) {
    int mask = 0;
    for (int a = 0; a < 3; ++a) {
      if (t[a].den == 0) continue;
      if (mask == 0 || less(t[a], t_min)) {
        t_min = t[a], mask = 1 << a;
      } else if (equal(t[a], t_min)) {
        mask |= 1 << a;
      }
    }
    return mask;
  }
  Time boundaryTime(int a, int plane) const {
    return d[a] > 0 ? Time{int64_t(plane) - o[a], d[a]}
                    : Time{int64_t(o[a]) - plane, -int64_t(d[a])};
  }
  static bool less(Time x, Time y) { return x.num * y.den < y.num * x.den; }
  static bool equal(Time x, Time y) { return x.num * y.den == y.num * x.den; }
  int startCell(int a) const { return d[a] < 0 ? o[a] - 1 : o[a]; }
  int cellAt(int a, Time t, int lo, int hi) const {
    int64_t p = int64_t(o[a]) * t.den + t.num * d[a];  // position * den
    int64_t fl = p >= 0 ? p / t.den : -((-p + t.den - 1) / t.den);
    int64_t c = positive(a) ? fl : (fl * t.den == p ? fl - 1 : fl);
    return int(glm::clamp<int64_t>(c, lo, hi));
  }
};

struct NoSlotVisitor {
  void operator()(int) const {}
};

namespace detail {

template <class Ray>
RDM_WALK_INLINE bool startWalk(const Ray& ray, const glm::ivec3& extent, glm::ivec3& cell,
                               int& mask, typename Ray::Time& t_start) {
  using Time = typename Ray::Time;
  Time t_enter = ray.zero(), t_exit{};
  bool entering = false, has_exit = false;
  mask = 0;
  for (int a = 0; a < 3; ++a) {
    if (!ray.moving(a)) {
      int c = ray.startCell(a);
      if (c < 0 || c >= extent[a]) return false;
      continue;
    }
    Time t_near = ray.boundaryTime(a, ray.positive(a) ? 0 : extent[a]);
    Time t_far = ray.boundaryTime(a, ray.positive(a) ? extent[a] : 0);
    if (Ray::less(t_enter, t_near)) {
      t_enter = t_near, mask = 1 << a, entering = true;
    } else if (entering && Ray::equal(t_enter, t_near)) {
      mask |= 1 << a;
    }
    if (!has_exit || Ray::less(t_far, t_exit)) t_exit = t_far, has_exit = true;
  }
  if (has_exit && !Ray::less(t_enter, t_exit)) return false;
  t_start = t_enter;
  for (int a = 0; a < 3; ++a) {
    if (mask & (1 << a)) {
      cell[a] = ray.positive(a) ? 0 : extent[a] - 1;
    } else if (entering && ray.moving(a)) {
      cell[a] = ray.cellAt(a, t_enter, 0, extent[a] - 1);
    } else {
      cell[a] = ray.startCell(a);
      if (cell[a] < 0 || cell[a] >= extent[a]) return false;
    }
  }
  return true;
}

template <class Ray>
RDM_WALK_INLINE int nextCrossing(const Ray& ray, const glm::ivec3& planes,
                                 typename Ray::Time& t_min) {
  int mask = 0;
  for (int a = 0; a < 3; ++a) {
    if (!ray.moving(a)) continue;
    auto t = ray.boundaryTime(a, planes[a]);
    if (mask == 0 || Ray::less(t, t_min)) {
      t_min = t, mask = 1 << a;
    } else if (Ray::equal(t, t_min)) {
      mask |= 1 << a;
    }
  }
  return mask;
}

template <class Ray>
int hitAxis(const Ray& ray, int mask) {
  return shared::entryAxis(mask, glm::vec3(float(ray.d[0]), float(ray.d[1]), float(ray.d[2])));
}

// The plain two-level walk: voxel steps in non-empty slots, one step across an empty slot.
// It defines traceVoxels' result, and walks the rays traceVoxels calls irregular.
template <class Ray, class Visitor>
TraceHit referenceWalk(const VoxelWorld& world, const Ray& ray, typename Ray::Time& t_hit,
                       Visitor&& visit) {
  TraceHit hit;
  const glm::ivec3 extent = world.voxelExtent();
  glm::ivec3 cell;
  int mask;
  typename Ray::Time t;
  if (!detail::startWalk(ray, extent, cell, mask, t)) return hit;
  const int max_steps = extent.x + extent.y + extent.z + 8;
  for (int step = 0; step < max_steps; ++step) {
    const glm::ivec3 slot = cell >> 4;
    const int slot_index = world.slotLinear(slot);
    visit(slot_index);
    const int32_t block = world.slots[slot_index];
    glm::ivec3 planes;
    if (block >= 0) {
      const glm::ivec3 l = cell & 15;
      const uint8_t palette = world.blocks[block].voxels[l.x + 16 * l.y + 256 * l.z];
      if (palette) {
        hit.hit = true, hit.voxel = cell, hit.palette = palette, hit.steps = step;
        hit.axis = step == 0 && mask == 0 ? -1 : detail::hitAxis(ray, mask);
        hit.started_solid = hit.axis < 0;
        t_hit = t;
        return hit;
      }
      for (int a = 0; a < 3; ++a) planes[a] = cell[a] + (ray.positive(a) ? 1 : 0);
      mask = detail::nextCrossing(ray, planes, t);
      for (int a = 0; a < 3; ++a) {
        if (mask & (1 << a)) cell[a] += ray.positive(a) ? 1 : -1;
      }
    } else {
      for (int a = 0; a < 3; ++a) planes[a] = (slot[a] + (ray.positive(a) ? 1 : 0)) * 16;
      mask = detail::nextCrossing(ray, planes, t);
      for (int a = 0; a < 3; ++a) {
        if (mask & (1 << a)) {
          cell[a] = ray.positive(a) ? planes[a] : planes[a] - 1;
        } else if (ray.moving(a)) {
          cell[a] = ray.cellAt(a, t, slot[a] * 16, slot[a] * 16 + 15);
        }
      }
    }
    if (mask == 0) return hit;  // cannot happen for a moving ray; keeps the loop honest
    for (int a = 0; a < 3; ++a) {
      if (cell[a] < 0 || cell[a] >= extent[a]) return hit;
    }
  }
  // Every walk ends within the grid's extent in steps; reaching the bound is a bug, not a miss.
  RDM_CHECK(!"the voxel walk ran past its loop bound");
  return hit;
}

}  // namespace detail

namespace detail {

// The walk's state. tn[a] is the time the ray leaves `cell` on axis a (never() on a still
// axis); every time is boundaryTime of an integer plane, as in referenceWalk.
template <class Ray>
struct WalkState {
  using Time = typename Ray::Time;
  glm::ivec3 cell;
  Time t;
  Time tn[3];
  int mask;                    // axes crossed to enter `cell`: they decide the hit normal
  glm::ivec3 off{0}, step{0};  // cell c's exit plane is c + off; step = +-1, 0 if still
};

template <class Ray>
RDM_WALK_INLINE void exitTimes(const Ray& ray, WalkState<Ray>& s) {
  for (int a = 0; a < 3; ++a)
    s.tn[a] = ray.moving(a) ? ray.boundaryTime(a, s.cell[a] + s.off[a]) : Ray::never();
}

// One voxel step: every axis that reaches the earliest exit time steps.
template <class Ray>
RDM_WALK_INLINE void voxelStep(const Ray& ray, WalkState<Ray>& s) {
  s.mask = Ray::earliest(s.tn, s.t);
  for (int a = 0; a < 3; ++a) {
    if (s.mask & (1 << a)) {
      s.cell[a] += s.step[a];
      s.tn[a] = ray.boundaryTime(a, s.cell[a] + s.off[a]);
    }
  }
}

// Leaves the current (empty) 4^3 brick where voxel steps would: the axes reaching the
// brick's exit time cross it; each other axis catches up by voxel steps to its cell at that
// time (at most 3), and joins the mask if it crosses a voxel plane exactly then.
template <class Ray>
RDM_WALK_INLINE void brickSkip(const Ray& ray, WalkState<Ray>& s) {
  using Time = typename Ray::Time;
  Time tb[3], t_exit;
  for (int a = 0; a < 3; ++a)
    tb[a] = ray.moving(a) ? ray.boundaryTime(a, (s.cell[a] & ~3) + 4 * s.off[a]) : Ray::never();
  int mask = Ray::earliest(tb, t_exit);
  Time t_entry[3] = {tb[0], tb[1], tb[2]};  // per axis in the mask: its plane's time
  for (int a = 0; a < 3; ++a) {
    if (mask & (1 << a)) {
      s.cell[a] = (s.cell[a] & ~3) + (s.off[a] ? 4 : -1);
      s.tn[a] = ray.boundaryTime(a, s.cell[a] + s.off[a]);
      continue;
    }
    for (int k = 0; k < 3 && !Ray::less(t_exit, s.tn[a]); ++k) {
      if (Ray::equal(t_exit, s.tn[a])) mask |= 1 << a, t_entry[a] = s.tn[a];
      s.cell[a] += s.step[a];
      s.tn[a] = ray.boundaryTime(a, s.cell[a] + s.off[a]);
    }
  }
  // The time as the lowest axis of the mask writes it, as a voxel step would (ExactRay's
  // fractions are not reduced).
  s.t = t_entry[mask & 1 ? 0 : (mask & 2 ? 1 : 2)], s.mask = mask;
}

// Crosses an empty slot in one step, exactly as referenceWalk does (the mask holds only the
// axes crossing the slot's planes).
template <class Ray>
RDM_WALK_INLINE void slotSkip(const Ray& ray, const glm::ivec3& slot, WalkState<Ray>& s) {
  glm::ivec3 planes;
  for (int a = 0; a < 3; ++a) planes[a] = (slot[a] + s.off[a]) * 16;
  s.mask = nextCrossing(ray, planes, s.t);
  for (int a = 0; a < 3; ++a) {
    if (s.mask & (1 << a)) {
      s.cell[a] = s.off[a] ? planes[a] : planes[a] - 1;
    } else if (ray.moving(a)) {
      s.cell[a] = ray.cellAt(a, s.t, slot[a] * 16, slot[a] * 16 + 15);
    }
  }
  exitTimes(ray, s);
}

}  // namespace detail

// Walks `ray` until the first solid voxel. `t_hit` receives the entry time. `visit(slot)`
// is called with the linear index of every slot the ray passes through (at least once per
// slot, in order). Same result as referenceWalk, bit for bit: empty slots are crossed in one
// step, empty 4^3 bricks of a block in one step that lands where voxel steps would.
template <class Ray, class Visitor = NoSlotVisitor>
TraceHit traceVoxels(const VoxelWorld& world, const Ray& ray, typename Ray::Time& t_hit,
                     Visitor&& visit = Visitor()) {
  if (!ray.regular()) return detail::referenceWalk(world, ray, t_hit, visit);
  TraceHit hit;
  const glm::ivec3 extent = world.voxelExtent();
  detail::WalkState<Ray> s;
  if (!detail::startWalk(ray, extent, s.cell, s.mask, s.t)) return hit;
  for (int a = 0; a < 3; ++a) {
    s.off[a] = ray.positive(a) ? 1 : 0;
    s.step[a] = ray.moving(a) ? (ray.positive(a) ? 1 : -1) : 0;
  }
  detail::exitTimes(ray, s);
  // Every step enters a new cell on some axis, and cells only advance.
  const int max_steps = extent.x + extent.y + extent.z + 8;
  int steps = 0;
  while (steps < max_steps) {
    const glm::ivec3 slot = s.cell >> 4;
    const int slot_index = world.slotLinear(slot);
    visit(slot_index);
    const int32_t block = world.slots[slot_index];
    if (block < 0) {
      ++steps;
      detail::slotSkip(ray, slot, s);
    } else {
      const BrickMasks& occ = world.occupancy[block];
      while (steps < max_steps && (s.cell >> 4) == slot) {
        ++steps;
        const glm::ivec3 l = s.cell & 15;
        const int brick = l.x >> 2 | (l.y >> 2) << 2 | (l.z >> 2) << 4;
        if (!(occ.bricks >> brick & 1)) {
          detail::brickSkip(ray, s);
          continue;
        }
        if (occ.voxels[brick] >> ((l.x & 3) | (l.y & 3) << 2 | (l.z & 3) << 4) & 1) {
          hit.hit = true, hit.voxel = s.cell, hit.steps = steps - 1;
          hit.palette = world.blocks[block].voxels[l.x + 16 * l.y + 256 * l.z];
          hit.axis = detail::hitAxis(ray, s.mask);
          hit.started_solid = hit.axis < 0;
          t_hit = s.t;
          return hit;
        }
        detail::voxelStep(ray, s);
      }
    }
    for (int a = 0; a < 3; ++a) {
      if (s.cell[a] < 0 || s.cell[a] >= extent[a]) return hit;
    }
  }
  // Every walk ends within the grid's extent in steps; reaching the bound is a bug, not a miss.
  RDM_CHECK(!"the voxel walk ran past its loop bound");
  return hit;
}

// Depth of a texel central ray: distance in world units from the integer voxel-unit
// origin to the entry of the first solid voxel; kSkyDepth on a miss; 0 if the start is solid.
// `slots`, when given, receives the linear index of every slot the ray passes through.
float exactCentralDepth(const VoxelWorld& world, const glm::ivec3& origin, const glm::ivec3& dir,
                        std::vector<uint32_t>* slots = nullptr);

}  // namespace rdm

#include "rdm/trace/float_walk.h"  // traceVoxels for FloatRay
