// traceVoxels for FloatRay with the three axes in one SSE2 register: every step is
// branch-free over the axes. The same float operations as FloatRay::boundaryTime and
// FloatRay::cellAt (sub, mul, add; no contraction), so the result is referenceWalk's, bit
// for bit (tests/trace/traversal_test.cpp compares them on every kind of ray).
#pragma once

#include <emmintrin.h>

#include <type_traits>

#include "rdm/trace/traversal.h"

namespace rdm {
namespace detail {

// Lane a (0..2) of v; the shuffle immediate must be a constant for clang.
inline int laneOfCell(__m128i v, int a) {
  if (a == 0) return _mm_cvtsi128_si32(v);
  return _mm_cvtsi128_si32(a == 1 ? _mm_shuffle_epi32(v, 0x55) : _mm_shuffle_epi32(v, 0xAA));
}

struct SseWalk {
  __m128 o, d, inv;
  __m128 o_times, inv_times;  // o and inv, with -inf and +inf on still lanes
  __m128 still;               // all ones on axes with d == 0 and on lane 3
  __m128i off;                // 1 where d > 0: cell c's exit plane is c + off
  __m128i step;               // +1, -1, or 0 on still axes
  __m128i cell;               // lane 3 is 0
  __m128 tn;                  // exit time of `cell` per axis, +inf on still lanes
  __m128 entered;             // all ones on the axes crossed to enter `cell`
  float t = 0.0f;

  explicit SseWalk(const FloatRay& ray) {
    o = _mm_setr_ps(ray.o.x, ray.o.y, ray.o.z, 0.0f);
    d = _mm_setr_ps(ray.d.x, ray.d.y, ray.d.z, 0.0f);
    inv = _mm_setr_ps(ray.inv.x, ray.inv.y, ray.inv.z, 0.0f);
    still = _mm_castsi128_ps(
        _mm_setr_epi32(-int(!ray.moving(0)), -int(!ray.moving(1)), -int(!ray.moving(2)), -1));
    const __m128 inf = _mm_set1_ps(std::numeric_limits<float>::infinity());
    o_times = select(still, _mm_sub_ps(_mm_setzero_ps(), inf), o);
    inv_times = select(still, inf, inv);
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
  // boundaryTime of `planes` per axis; +inf on still lanes, where the origin is -inf and
  // the inverse +inf (plane + inf) * inf.
  __m128 times(__m128i planes) const {
    return _mm_mul_ps(_mm_sub_ps(_mm_cvtepi32_ps(planes), o_times), inv_times);
  }
  __m128 exitTimes(__m128i c) const { return times(_mm_add_epi32(c, off)); }
  int lane(int a) const { return laneOfCell(cell, a); }
  glm::ivec3 cellVec() const { return {lane(0), lane(1), lane(2)}; }
  void setCell(const glm::ivec3& c) { cell = _mm_setr_epi32(c.x, c.y, c.z, 0); }
  int mask() const { return _mm_movemask_ps(entered) & 7; }

  // Exit times of the cubes of side 2^bits at integer coordinates `cube` (cube + off, scaled).
  __m128 cubeTimes(__m128i cube, int bits) const {
    return times(_mm_slli_epi32(_mm_add_epi32(cube, off), bits));
  }
  // One DDA step at any level: every axis reaching the earliest of `exit` advances `at`.
  void cubeStep(const __m128& exit, __m128i& at) {
    const __m128 t_min = minLanes(exit);
    entered = _mm_cmpeq_ps(exit, t_min);
    at = _mm_add_epi32(at, _mm_and_si128(step, _mm_castps_si128(entered)));
    t = _mm_cvtss_f32(t_min);
  }
  void voxelStep() {
    cubeStep(tn, cell);
    tn = select(entered, exitTimes(cell), tn);
  }

  // Crosses the empty 2 x 2 x 2 group of slots around `slot` and updates `slot` as
  // referenceWalk's slot skips through it would: the axes reaching the group's exit time
  // enter the next group; every other moving axis is in the half past the group's middle
  // plane if the ray has crossed it by then, and joins the mask if it crosses it exactly
  // then (the last slot skip would have crossed it too).
  void pairStep(__m128i& slot) {
    __m128i pair = _mm_srai_epi32(slot, 1);
    const __m128 mid =
        times(_mm_slli_epi32(_mm_add_epi32(_mm_slli_epi32(pair, 1), _mm_set1_epi32(1)), 4));
    cubeStep(cubeTimes(pair, 5), pair);
    const __m128 tv = _mm_set1_ps(t);
    const __m128 other =
        _mm_andnot_ps(_mm_or_ps(entered, still), _mm_castsi128_ps(_mm_set1_epi32(-1)));
    // Going up, the upper half once the middle is crossed; going down, the lower half.
    const __m128i upper = _mm_xor_si128(_mm_castps_si128(_mm_cmple_ps(mid, tv)),
                                        _mm_sub_epi32(off, _mm_set1_epi32(1)));
    const __m128i inside = _mm_sub_epi32(_mm_slli_epi32(pair, 1), upper);
    const __m128i first =
        _mm_sub_epi32(_mm_add_epi32(_mm_slli_epi32(pair, 1), _mm_set1_epi32(1)), off);
    slot = select(entered, first, select(other, inside, slot));
    entered = _mm_or_ps(entered, _mm_and_ps(other, _mm_cmpeq_ps(mid, tv)));
  }

  // The cells at time t after a step at a coarser level (cube of side 2^bits at `cube`):
  // axes in `entered` take the cube's first cell; every other moving axis the unique cell
  // c of the cube with T(entry plane of c) <= t < T(exit plane of c), as FloatRay::cellAt
  // finds it. Computed from cellAt's first guess, checked, and cellAt itself if the check
  // fails. With `voxel_mask`, axes crossing a voxel plane exactly at t join `entered`.
  void cellsAt(const FloatRay& ray, __m128i cube, int bits, bool voxel_mask) {
    const __m128i lo = _mm_slli_epi32(cube, bits);
    const __m128i hi = _mm_add_epi32(lo, _mm_set1_epi32((1 << bits) - 1));
    const __m128 up = _mm_castsi128_ps(_mm_cmpgt_epi32(off, _mm_setzero_si128()));
    const __m128 tv = _mm_set1_ps(t);
    const __m128 p = _mm_add_ps(o, _mm_mul_ps(tv, d));
    const __m128i trunc = _mm_cvttps_epi32(p);
    const __m128 ft = _mm_cvtepi32_ps(trunc);
    // floor(p) = trunc - (trunc > p); ceil(p) - 1 = trunc + (trunc < p) - 1.
    const __m128i fl = _mm_add_epi32(trunc, _mm_castps_si128(_mm_cmpgt_ps(ft, p)));
    const __m128i cm1 = _mm_sub_epi32(_mm_sub_epi32(trunc, _mm_castps_si128(_mm_cmplt_ps(ft, p))),
                                      _mm_set1_epi32(1));
    __m128i guess = select(up, fl, cm1);
    guess = select(_mm_castsi128_ps(_mm_cmplt_epi32(guess, lo)), lo, guess);
    guess = select(_mm_castsi128_ps(_mm_cmpgt_epi32(guess, hi)), hi, guess);
    cell = select(entered, select(up, lo, hi), select(still, cell, guess));
    __m128 t_out = exitTimes(cell);
    __m128 t_in = times(_mm_sub_epi32(_mm_add_epi32(cell, _mm_set1_epi32(1)), off));
    const __m128 need =
        _mm_andnot_ps(_mm_or_ps(entered, still), _mm_castsi128_ps(_mm_set1_epi32(-1)));
    const __m128 ok = _mm_and_ps(_mm_cmple_ps(t_in, tv), _mm_cmpgt_ps(t_out, tv));
    if (_mm_movemask_ps(_mm_andnot_ps(ok, need)) & 7) {
      glm::ivec3 c = cellVec();
      const int m = _mm_movemask_ps(need);
      for (int a = 0; a < 3; ++a) {
        if (m & (1 << a))
          c[a] = ray.cellAt(a, t, c[a] & ~((1 << bits) - 1), (c[a] | ((1 << bits) - 1)));
      }
      setCell(c);
      t_out = exitTimes(cell);
      t_in = times(_mm_sub_epi32(_mm_add_epi32(cell, _mm_set1_epi32(1)), off));
    }
    if (voxel_mask) entered = _mm_or_ps(entered, _mm_and_ps(need, _mm_cmpeq_ps(t_in, tv)));
    tn = t_out;
  }
};

inline int laneOf(__m128i v, int a) {
  return laneOfCell(v, a);
}
inline bool sameLanes(__m128i a, __m128i b) {
  return _mm_movemask_epi8(_mm_cmpeq_epi32(a, b)) == 0xFFFF;
}

}  // namespace detail

// traceVoxels for float rays: a three-level DDA (slots, 4^3 bricks, voxels), each level
// with its own exit times. Crossing empty slots never computes cells; crossing empty bricks
// neither; cells are found once, on entering a non-empty slot or brick, where
// referenceWalk's voxel steps or slot skip would have put them (SseWalk::cellsAt).
template <class Visitor = NoSlotVisitor>
TraceHit traceVoxels(const VoxelWorld& world, const FloatRay& ray, float& t_hit,
                     Visitor&& visit = Visitor()) {
  if (!ray.regular()) return detail::referenceWalk(world, ray, t_hit, visit);
  // Steps over 2 x 2 x 2 empty slots skip slots, so only a walk without a visitor takes them.
  constexpr bool kPairSteps = std::is_same_v<std::decay_t<Visitor>, NoSlotVisitor>;
  TraceHit hit;
  const glm::ivec3 extent = world.voxelExtent();
  // An origin whose start cell is in the grid starts there at t = 0 with no axis crossed,
  // as startWalk decides (its near planes are not ahead, its far planes are).
  glm::ivec3 start;
  int start_mask = 0;
  float t0 = 0.0f;
  bool inside = true;
  for (int a = 0; a < 3; ++a) {
    start[a] = ray.startCell(a);
    inside = inside && start[a] >= 0 && start[a] < extent[a];
  }
  if (!inside && !detail::startWalk(ray, extent, start, start_mask, t0)) return hit;
  detail::SseWalk w(ray);
  w.setCell(start);
  w.t = t0;
  w.entered = _mm_castsi128_ps(
      _mm_setr_epi32(-(start_mask & 1), -(start_mask >> 1 & 1), -(start_mask >> 2 & 1), 0));
  w.tn = w.exitTimes(w.cell);
  __m128i slot = _mm_srai_epi32(w.cell, 4), brick = _mm_srai_epi32(w.cell, 2);
  __m128 brick_exit = w.cubeTimes(brick, 2);
  const __m128i slot_max = _mm_setr_epi32(world.size.x - 1, world.size.y - 1, world.size.z - 1, 0);
  bool cell_known = true, after_slot_step = false;
  // Every step enters a new cell, brick or slot on some axis, and they only advance.
  const int max_steps = extent.x + extent.y + extent.z + 8;
  int steps = 0;
  while (steps < max_steps) {
    const int slot_index = world.slotLinear(
        {detail::laneOf(slot, 0), detail::laneOf(slot, 1), detail::laneOf(slot, 2)});
    visit(slot_index);
    const int32_t block = world.slots[slot_index];
    if (block < 0) {
      ++steps;
      if (kPairSteps && world.slot_steps[size_t(slot_index)] == kEmptySlotGroup) {
        w.pairStep(slot);
      } else {
        w.cubeStep(w.cubeTimes(slot, 4), slot);
      }
      after_slot_step = true;
    } else {
      if (after_slot_step) {
        w.cellsAt(ray, slot, 4, false);
        brick = _mm_srai_epi32(w.cell, 2);
        brick_exit = w.cubeTimes(brick, 2);
        cell_known = true, after_slot_step = false;
      }
      const BrickMasks& occ = world.occupancy[block];
      while (steps < max_steps) {
        const int b = (detail::laneOf(brick, 0) & 3) | (detail::laneOf(brick, 1) & 3) << 2 |
                      (detail::laneOf(brick, 2) & 3) << 4;
        if (!(occ.bricks >> b & 1)) {
          ++steps;
          w.cubeStep(brick_exit, brick);
          brick_exit = w.cubeTimes(brick, 2);
          cell_known = false;
        } else {
          if (!cell_known) w.cellsAt(ray, brick, 2, true), cell_known = true;
          const uint64_t bits = occ.voxels[b];
          for (;;) {
            const int x = w.lane(0), y = w.lane(1), z = w.lane(2);
            if (bits >> ((x & 3) | (y & 3) << 2 | (z & 3) << 4) & 1) {
              hit.hit = true, hit.voxel = {x, y, z}, hit.steps = steps;
              hit.palette = world.blocks[block].voxels[(x & 15) + 16 * (y & 15) + 256 * (z & 15)];
              hit.axis = detail::hitAxis(ray, w.mask());
              hit.started_solid = hit.axis < 0;
              t_hit = w.t;
              return hit;
            }
            if (++steps >= max_steps) break;
            w.voxelStep();
            const __m128i now = _mm_srai_epi32(w.cell, 2);
            if (!detail::sameLanes(now, brick)) {
              brick = now;
              brick_exit = w.cubeTimes(brick, 2);
              break;
            }
          }
        }
        if (!detail::sameLanes(_mm_srai_epi32(brick, 2), slot)) break;
      }
      slot = _mm_srai_epi32(brick, 2);
    }
    const __m128i outside =
        _mm_or_si128(_mm_cmplt_epi32(slot, _mm_setzero_si128()), _mm_cmpgt_epi32(slot, slot_max));
    if (_mm_movemask_epi8(outside)) return hit;
  }
  // Every walk ends within the grid's extent in steps; reaching the bound is a bug, not a miss.
  RDM_CHECK(!"the voxel walk ran past its loop bound");
  return hit;
}

}  // namespace rdm
