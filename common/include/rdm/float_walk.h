// traceVoxels for FloatRay with the three axes in one SSE2 register: every step is
// branch-free over the axes. The same float operations as FloatRay::boundaryTime and
// FloatRay::cellAt (sub, mul, add; no contraction), so the result is referenceWalk's, bit
// for bit (tests/traversal_test.cpp compares them on every kind of ray).
#pragma once

#include <emmintrin.h>

#include "rdm/traversal.h"

namespace rdm {
namespace detail {

struct SseWalk {
  __m128 o, d, inv;
  __m128 still;    // all ones on axes with d == 0 and on lane 3
  __m128i off;     // 1 where d > 0: cell c's exit plane is c + off
  __m128i step;    // +1, -1, or 0 on still axes
  __m128i cell;    // lane 3 is 0
  __m128 tn;       // exit time of `cell` per axis, +inf on still lanes
  __m128 entered;  // all ones on the axes crossed to enter `cell`
  float t = 0.0f;

  explicit SseWalk(const FloatRay& ray) {
    o = _mm_setr_ps(ray.o.x, ray.o.y, ray.o.z, 0.0f);
    d = _mm_setr_ps(ray.d.x, ray.d.y, ray.d.z, 0.0f);
    inv = _mm_setr_ps(ray.inv.x, ray.inv.y, ray.inv.z, 0.0f);
    still = _mm_castsi128_ps(
        _mm_setr_epi32(-int(!ray.moving(0)), -int(!ray.moving(1)), -int(!ray.moving(2)), -1));
    off = _mm_setr_epi32(ray.positive(0), ray.positive(1), ray.positive(2), 0);
    step = _mm_setr_epi32(ray.moving(0) ? (ray.positive(0) ? 1 : -1) : 0,
                          ray.moving(1) ? (ray.positive(1) ? 1 : -1) : 0,
                          ray.moving(2) ? (ray.positive(2) ? 1 : -1) : 0, 0);
  }

  static __m128 select(__m128 m, __m128 a, __m128 b) {
    return _mm_or_ps(_mm_and_ps(m, a), _mm_andnot_ps(m, b));
  }
  static __m128i select(__m128 m, __m128i a, __m128i b) {
    const __m128i mi = _mm_castps_si128(m);
    return _mm_or_si128(_mm_and_si128(mi, a), _mm_andnot_si128(mi, b));
  }
  // The smallest lane, in every lane.
  static __m128 minLanes(__m128 v) {
    v = _mm_min_ps(v, _mm_shuffle_ps(v, v, _MM_SHUFFLE(2, 3, 0, 1)));
    return _mm_min_ps(v, _mm_shuffle_ps(v, v, _MM_SHUFFLE(1, 0, 3, 2)));
  }
  // boundaryTime of `planes` per axis; +inf on still lanes.
  __m128 times(__m128i planes) const {
    const __m128 t = _mm_mul_ps(_mm_sub_ps(_mm_cvtepi32_ps(planes), o), inv);
    return select(still, _mm_set1_ps(std::numeric_limits<float>::infinity()), t);
  }
  __m128 exitTimes(__m128i c) const { return times(_mm_add_epi32(c, off)); }
  int lane(int a) const {
    const __m128i v = a == 0 ? cell : _mm_shuffle_epi32(cell, a == 1 ? 0x55 : 0xAA);
    return _mm_cvtsi128_si32(v);
  }
  glm::ivec3 cellVec() const { return {lane(0), lane(1), lane(2)}; }
  void setCell(const glm::ivec3& c) { cell = _mm_setr_epi32(c.x, c.y, c.z, 0); }
  int mask() const { return _mm_movemask_ps(entered) & 7; }

  void voxelStep() {
    const __m128 t_min = minLanes(tn);
    entered = _mm_cmpeq_ps(tn, t_min);
    cell = _mm_add_epi32(cell, _mm_and_si128(step, _mm_castps_si128(entered)));
    tn = select(entered, exitTimes(cell), tn);
    t = _mm_cvtss_f32(t_min);
  }

  // detail::brickSkip on four lanes: cross the brick's exit planes reached first; every
  // other axis catches up (at most 3 voxel steps) and joins the mask on an exact tie.
  void brickSkip() {
    const __m128i base = _mm_andnot_si128(_mm_set1_epi32(3), cell);
    const __m128 tb = times(_mm_add_epi32(base, _mm_slli_epi32(off, 2)));
    const __m128 t_exit = minLanes(tb);
    entered = _mm_cmpeq_ps(tb, t_exit);
    // base + 4 going up, base - 1 going down: base + 5 off - 1.
    const __m128i next = _mm_sub_epi32(
        _mm_add_epi32(base, _mm_add_epi32(_mm_slli_epi32(off, 2), off)), _mm_set1_epi32(1));
    cell = select(entered, next, cell);
    tn = select(entered, exitTimes(cell), tn);
    for (int k = 0; k < 3; ++k) {
      const __m128 behind = _mm_cmple_ps(tn, t_exit);
      if (!_mm_movemask_ps(behind)) break;
      entered = _mm_or_ps(entered, _mm_and_ps(behind, _mm_cmpeq_ps(tn, t_exit)));
      cell = _mm_add_epi32(cell, _mm_and_si128(step, _mm_castps_si128(behind)));
      tn = select(behind, exitTimes(cell), tn);
    }
    t = _mm_cvtss_f32(t_exit);
  }

  // detail::slotSkip: cross the slot's exit planes reached first; every other moving axis
  // takes FloatRay::cellAt's answer, computed here as its first guess (floor, or ceil - 1,
  // clamped into the slot) and kept only where cellAt's loops would not move it.
  void slotSkip(const FloatRay& ray, const glm::ivec3& slot) {
    const __m128i lo = _mm_slli_epi32(_mm_setr_epi32(slot.x, slot.y, slot.z, 0), 4);
    const __m128i hi = _mm_add_epi32(lo, _mm_set1_epi32(15));
    const __m128 tb = times(_mm_add_epi32(lo, _mm_slli_epi32(off, 4)));
    const __m128 t_exit = minLanes(tb);
    entered = _mm_cmpeq_ps(tb, t_exit);
    const __m128 p = _mm_add_ps(o, _mm_mul_ps(t_exit, d));
    const __m128i trunc = _mm_cvttps_epi32(p);
    const __m128 ft = _mm_cvtepi32_ps(trunc);
    // floor(p) = trunc - (trunc > p); ceil(p) - 1 = trunc + (trunc < p) - 1.
    const __m128i fl = _mm_add_epi32(trunc, _mm_castps_si128(_mm_cmpgt_ps(ft, p)));
    const __m128i cm1 = _mm_sub_epi32(_mm_sub_epi32(trunc, _mm_castps_si128(_mm_cmplt_ps(ft, p))),
                                      _mm_set1_epi32(1));
    const __m128 up = _mm_castsi128_ps(_mm_cmpgt_epi32(off, _mm_setzero_si128()));
    __m128i guess = select(up, fl, cm1);
    guess = select(_mm_castsi128_ps(_mm_cmplt_epi32(guess, lo)), lo, guess);
    guess = select(_mm_castsi128_ps(_mm_cmpgt_epi32(guess, hi)), hi, guess);
    // lo + 16 going up, lo - 1 going down: lo + 17 off - 1.
    const __m128i next = _mm_sub_epi32(
        _mm_add_epi32(lo, _mm_add_epi32(_mm_slli_epi32(off, 4), off)), _mm_set1_epi32(1));
    cell = select(entered, next, select(still, cell, guess));
    const __m128 t_out = exitTimes(cell);
    // cellAt keeps its guess c when (c is the exit-side bound or T(exit plane) > t) and (c
    // is the entry-side bound or T(entry plane) <= t).
    const __m128 t_in = times(_mm_sub_epi32(_mm_add_epi32(cell, _mm_set1_epi32(1)), off));
    const __m128i exit_bound = select(up, hi, lo), entry_bound = select(up, lo, hi);
    const __m128 ok_exit =
        _mm_or_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(cell, exit_bound)), _mm_cmpgt_ps(t_out, t_exit));
    const __m128 ok_entry =
        _mm_or_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(cell, entry_bound)), _mm_cmple_ps(t_in, t_exit));
    const __m128 checked = _mm_or_ps(still, entered);
    t = _mm_cvtss_f32(t_exit);
    tn = t_out;
    if ((_mm_movemask_ps(_mm_or_ps(checked, _mm_and_ps(ok_exit, ok_entry))) & 7) == 7) return;
    glm::ivec3 c = cellVec();
    const int m = mask();
    for (int a = 0; a < 3; ++a) {
      if (!(m & (1 << a)) && ray.moving(a))
        c[a] = ray.cellAt(a, t, slot[a] * 16, slot[a] * 16 + 15);
    }
    setCell(c);
    tn = exitTimes(cell);
  }
};

}  // namespace detail

// traceVoxels for float rays: the walk of the generic traceVoxels, on SSE lanes.
template <class Visitor = NoSlotVisitor>
TraceHit traceVoxels(const VoxelWorld& world, const FloatRay& ray, float& t_hit,
                     Visitor&& visit = Visitor()) {
  if (!ray.regular()) return detail::referenceWalk(world, ray, t_hit, visit);
  TraceHit hit;
  const glm::ivec3 extent = world.voxelExtent();
  glm::ivec3 start;
  int start_mask;
  float t0;
  if (!detail::startWalk(ray, extent, start, start_mask, t0)) return hit;
  detail::SseWalk w(ray);
  w.setCell(start);
  w.t = t0;
  w.entered = _mm_castsi128_ps(
      _mm_setr_epi32(-(start_mask & 1), -(start_mask >> 1 & 1), -(start_mask >> 2 & 1), 0));
  w.tn = w.exitTimes(w.cell);
  const __m128i grid_max = _mm_setr_epi32(extent.x - 1, extent.y - 1, extent.z - 1, 0);
  const int max_steps = extent.x + extent.y + extent.z + 8;
  int steps = 0;
  glm::ivec3 c = start;
  while (steps < max_steps) {
    const glm::ivec3 slot = c >> 4;
    const int slot_index = world.slotLinear(slot);
    visit(slot_index);
    const int32_t block = world.slots[slot_index];
    if (block < 0) {
      ++steps;
      w.slotSkip(ray, slot);
      c = w.cellVec();
    } else {
      const BrickMasks& occ = world.occupancy[block];
      const glm::ivec3 base = slot * 16;
      while (steps < max_steps) {
        ++steps;
        const glm::ivec3 l = c - base;
        const int brick = l.x >> 2 | (l.y >> 2) << 2 | (l.z >> 2) << 4;
        if (!(occ.bricks >> brick & 1)) {
          w.brickSkip();
        } else if (occ.voxels[brick] >> ((l.x & 3) | (l.y & 3) << 2 | (l.z & 3) << 4) & 1) {
          hit.hit = true, hit.voxel = c, hit.steps = steps - 1;
          hit.palette = world.blocks[block].voxels[l.x + 16 * l.y + 256 * l.z];
          hit.axis = detail::hitAxis(ray, w.mask());
          hit.started_solid = hit.axis < 0;
          t_hit = w.t;
          return hit;
        } else {
          w.voxelStep();
        }
        c = w.cellVec();
        if (((c.x - base.x) | (c.y - base.y) | (c.z - base.z)) & ~15) break;
      }
    }
    const __m128i outside = _mm_or_si128(_mm_cmplt_epi32(w.cell, _mm_setzero_si128()),
                                         _mm_cmpgt_epi32(w.cell, grid_max));
    if (_mm_movemask_epi8(outside)) return hit;
  }
  hit.bound_exceeded = true;
  return hit;
}

}  // namespace rdm
