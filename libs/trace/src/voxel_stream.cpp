// traceVoxelStream: one step kind, leaving the empty cube around the cell (rdm_walk.h's
// walkLeave, plus 8^3 octants and 2 x 2 x 2 groups of slots), on every lane of a Highway
// vector. Compiled once per x86 target (foreach_target) and picked at run time. Bit identity
// with referenceWalk needs the same float operations per lane: sub, mul and add without
// contraction (CMake sets -ffp-contract=off), and an exact floor.
#include "rdm/trace/voxel_stream.h"

#include <algorithm>
#include <cstring>

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "voxel_stream.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include "rdm/base/check.h"
#include "rdm/transport/rdm_shared_cpp.h"

HWY_BEFORE_NAMESPACE();
namespace rdm {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

using DF = hn::ScalableTag<float>;
using DI = hn::RebindToSigned<DF>;
using DU = hn::RebindToUnsigned<DF>;
using VF = hn::Vec<DF>;
using VI = hn::Vec<DI>;
using MI = hn::Mask<DI>;

constexpr size_t kLanes = HWY_LANES(float);
// BrickMasks as 32-bit words: the brick word pair, then 64 voxel word pairs (little endian).
static_assert(sizeof(BrickMasks) == 520, "BrickMasks is read as 130 packed 32-bit words");

// The lanes' walks, one array per quantity (structure of arrays), in walk coordinates: an
// axis with d < 0 is mirrored (x -> -x, so the cell c becomes ~c = -c - 1), which makes every
// moving axis go up. Mirroring is exact: every boundary time, floor and comparison of the
// mirrored walk equals the unmirrored one's (float negation is exact, and rounding is
// symmetric), and 2^k-aligned cubes stay aligned. A lane with ray < 0 is parked: its cell is
// (0, 0, 0) and its steps are ignored.
struct StreamLanes {
  alignas(64) float o[3][kLanes];
  alignas(64) float d[3][kLanes];  // >= +0: +-0 on a still axis
  alignas(64) float inv[3][kLanes];
  alignas(64) float o_times[3][kLanes];    // o, -inf on a still axis
  alignas(64) float inv_times[3][kLanes];  // 1 / d, +inf on a still axis: its times are +inf
  alignas(64) int32_t flip[3][kLanes];     // -1 on a mirrored axis, else 0: cell = ~c or c
  alignas(64) int32_t cell[3][kLanes];
  alignas(64) float t[kLanes];
  alignas(64) int32_t mask[kLanes];
  alignas(64) int32_t steps[kLanes];
  alignas(64) int32_t ray[kLanes];
  alignas(64) int32_t solid[kLanes];  // the last step found the cell solid
  alignas(64) int32_t base[kLanes];   // the cell's block's first occupancy word, at the last step
};

// The per-ray work done outside the vectors: settling rays that do not walk, and writing
// each walked ray's result.
class StreamIo {
 public:
  StreamIo(const VoxelWorld& world, std::span<const FloatRay> rays, std::span<TraceHit> hits,
           std::span<float> t_hits)
      : world_(world), rays_(rays), hits_(hits), t_hits_(t_hits) {}

  // The result of a ray that does not walk: an irregular one takes referenceWalk, and a
  // regular one that misses the grid gets no hit.
  void settle(size_t i) {
    const FloatRay& ray = rays_[i];
    hits_[i] = ray.regular() ? TraceHit()
                             : detail::referenceWalk(world_, ray, t_hits_[i], NoSlotVisitor());
  }
  // Writes the result of the ray in `lane`. The hit voxel's palette byte is likely a cache
  // miss (4 KiB per block): it is prefetched here and read in resolvePalettes.
  void finish(StreamLanes& s, size_t lane) {
    const size_t i = size_t(s.ray[lane]);
    // Field by field: a whole TraceHit() temporary compiles to overlapping stores and
    // reloads that stall store forwarding (12 % of the stream's time on camera rays).
    TraceHit& hit = hits_[i];
    hit.steps = s.steps[lane];
    hit.palette = 0;
    hit.hit = s.solid[lane] != 0;
    if (!hit.hit) {
      hit.started_solid = false, hit.voxel = glm::ivec3(0), hit.axis = -1;
      return;
    }
    const glm::ivec3 v(s.cell[0][lane] ^ s.flip[0][lane], s.cell[1][lane] ^ s.flip[1][lane],
                       s.cell[2][lane] ^ s.flip[2][lane]);
    hit.voxel = v;
    hit.axis = s.mask[lane] == 0 ? -1 : shared::entryAxis(s.mask[lane], rays_[i].d);
    hit.started_solid = hit.axis < 0;
    t_hits_[i] = s.t[lane];
    const glm::ivec3 l = v & 15;
    const uint8_t* palette =
        &world_.blocks[size_t(s.base[lane] / kOccupancyWords)].voxels[l.x + 16 * l.y + 256 * l.z];
    __builtin_prefetch(palette);
    pending_[pending_count_++] = {&hit, palette};
    if (pending_count_ == kPending) resolvePalettes();
  }
  void resolvePalettes() {
    for (int k = 0; k < pending_count_; ++k) pending_[k].hit->palette = *pending_[k].palette;
    pending_count_ = 0;
  }

 private:
  const VoxelWorld& world_;
  std::span<const FloatRay> rays_;
  std::span<TraceHit> hits_;
  std::span<float> t_hits_;
  struct PendingPalette {
    TraceHit* hit;
    const uint8_t* palette;
  };
  static constexpr int kPending = 64;
  PendingPalette pending_[kPending];
  int pending_count_ = 0;
};

// Bit `bit` (0..31) of each lane's word.
HWY_INLINE MI bitSet(VI word, VI bit) {
  const DU du;
  const DI di;
  const auto shifted = hn::BitCast(du, word) >> hn::BitCast(du, bit);
  return hn::RebindMask(di, hn::Ne(hn::And(shifted, hn::Set(du, 1u)), hn::Zero(du)));
}

// One walkCellFix of an axis going up, on every lane: c moves up once the ray has reached
// its upper plane at t, else down if it has not reached its lower one.
HWY_INLINE VI cellFix(VF o, VF inv, VF t, VI c, VI lo, VI hi) {
  const DF df;
  const DI di;
  const VF cf = hn::ConvertTo(df, c);  // c + 1 is exact in float too (|c| < 2^24)
  const MI reached_upper =
      hn::RebindMask(di, hn::Le(hn::Mul(hn::Sub(hn::Add(cf, hn::Set(df, 1.0f)), o), inv), t));
  const MI before_lower = hn::RebindMask(di, hn::Gt(hn::Mul(hn::Sub(cf, o), inv), t));
  const MI inc = hn::And(hn::Lt(c, hi), reached_upper);
  const MI dec = hn::AndNot(inc, hn::And(hn::Gt(c, lo), before_lower));
  return hn::Add(hn::Sub(c, hn::VecFromMask(di, inc)), hn::VecFromMask(di, dec));
}

// walkCellAt of an axis going up, on every lane: the cell at time t, within [lo, hi].
HWY_INLINE VI cellAt(VF o, VF d, VF inv, VF t, VI lo, VI hi) {
  const VF p = hn::Add(o, hn::Mul(t, d));
  VI c = hn::Min(hn::Max(hn::ConvertTo(DI(), hn::Floor(p)), lo), hi);
  c = cellFix(o, inv, t, c, lo, hi);
  return cellFix(o, inv, t, c, lo, hi);
}

// The cube a lane leaves this step, as block-local masks: low = ~(side - 1).
struct Cubes {
  VI low, side, base;
  VI grain;  // 15 when the cube is a slot or more: a mask joins only at slot planes
  MI slot_empty, solid;
};

HWY_INLINE Cubes classify(const VoxelWorld& world, const int32_t* occupancy, const VI* cell) {
  const DI di;
  const VI sx = hn::ShiftRight<4>(cell[0]), sy = hn::ShiftRight<4>(cell[1]);
  const VI sz = hn::ShiftRight<4>(cell[2]);
  const VI slot = hn::Add(
      sx, hn::Mul(hn::Set(di, world.size.x), hn::Add(sy, hn::Mul(hn::Set(di, world.size.y), sz))));
  // VoxelWorld::slot_steps: the slot's first occupancy word, or which empty cube it is in.
  const VI entry = hn::GatherIndex(di, world.slot_steps.data(), slot);
  const MI slot_empty = hn::Lt(entry, hn::Zero(di));
  const MI group_empty = hn::Eq(entry, hn::Set(di, kEmptySlotGroup));
  const VI base = hn::Max(entry, hn::Zero(di));
  const VI m3 = hn::Set(di, 3);
  const VI bx = hn::And(hn::ShiftRight<2>(cell[0]), m3),
           by = hn::And(hn::ShiftRight<2>(cell[1]), m3);
  const VI bz = hn::And(hn::ShiftRight<2>(cell[2]), m3);
  const VI brick = hn::Or(bx, hn::Or(hn::ShiftLeft<2>(by), hn::ShiftLeft<4>(bz)));
  const VI bricks_word = hn::GatherIndex(di, occupancy, hn::Add(base, hn::ShiftRight<5>(brick)));
  const VI m31 = hn::Set(di, 31);
  const MI brick_full = hn::AndNot(slot_empty, bitSet(bricks_word, hn::And(brick, m31)));
  // The 8^3 octant holding the brick is empty when its 8 brick bits are 0; they sit in the
  // same 32-bit half as the brick's (bz >> 1 picks the half), at 0x00330033 << (2 ox + 8 oy).
  const DU du;
  const VI octant_shift =
      hn::Add(hn::ShiftLeft<1>(hn::ShiftRight<1>(bx)), hn::ShiftLeft<3>(hn::ShiftRight<1>(by)));
  const auto octant_bits = hn::Shl(hn::Set(du, 0x00330033u), hn::BitCast(du, octant_shift));
  const MI octant_empty =
      hn::RebindMask(di, hn::Eq(hn::And(hn::BitCast(du, bricks_word), octant_bits), hn::Zero(du)));
  const VI vx = hn::And(cell[0], m3), vy = hn::And(cell[1], m3), vz = hn::And(cell[2], m3);
  const VI voxel = hn::Or(vx, hn::Or(hn::ShiftLeft<2>(vy), hn::ShiftLeft<4>(vz)));
  const VI word = hn::Add(hn::Add(base, hn::Set(di, 2)),
                          hn::Add(hn::ShiftLeft<1>(brick), hn::ShiftRight<5>(voxel)));
  const VI voxel_word = hn::GatherIndex(di, occupancy, word);
  Cubes c;
  c.slot_empty = slot_empty;
  c.base = base;
  c.solid = hn::And(brick_full, bitSet(voxel_word, hn::And(voxel, m31)));
  c.low = hn::IfThenElse(
      slot_empty, hn::IfThenElse(group_empty, hn::Set(di, -32), hn::Set(di, -16)),
      hn::IfThenElse(brick_full, hn::Set(di, -1),
                     hn::IfThenElse(octant_empty, hn::Set(di, -8), hn::Set(di, -4))));
  c.grain = hn::IfThenElseZero(slot_empty, hn::Set(di, 15));
  c.side = hn::Sub(hn::Zero(di), c.low);
  return c;
}

// One lane-parallel walkLeave of the cubes `c`; returns the axes' cells and the new mask.
struct Leave {
  VI cell[3];
  VF t;
  VI mask;
};

HWY_INLINE Leave leave(const StreamLanes& s, const VI* cell, const Cubes& c) {
  const DF df;
  const DI di;
  VI lo[3];
  VF exit_time[3];
  for (int a = 0; a < 3; ++a) {
    lo[a] = hn::And(cell[a], c.low);
    exit_time[a] =
        hn::Mul(hn::Sub(hn::ConvertTo(df, hn::Add(lo[a], c.side)), hn::Load(df, s.o_times[a])),
                hn::Load(df, s.inv_times[a]));
  }
  Leave out;
  out.t = hn::Min(hn::Min(exit_time[0], exit_time[1]), exit_time[2]);
  out.mask = hn::Zero(di);
  const VI hi_offset = hn::Sub(c.side, hn::Set(di, 1));
  for (int a = 0; a < 3; ++a) {
    const VF o = hn::Load(df, s.o[a]), d = hn::Load(df, s.d[a]), inv = hn::Load(df, s.inv[a]);
    const MI exits = hn::RebindMask(di, hn::Eq(exit_time[a], out.t));
    const MI moving = hn::RebindMask(di, hn::Gt(d, hn::Zero(df)));
    const VI at = cellAt(o, d, inv, out.t, lo[a], hn::Add(lo[a], hi_offset));
    // An axis that crosses a voxel plane exactly at t (a slot plane, when the cube is a slot
    // or a group of slots) joins the mask, as the smaller steps through the cube would.
    const MI enters_at_t =
        hn::RebindMask(di, hn::Eq(hn::Mul(hn::Sub(hn::ConvertTo(df, at), o), inv), out.t));
    const MI aligned = hn::Eq(hn::And(at, c.grain), hn::Zero(di));
    const MI joins = hn::And(aligned, hn::And(hn::Ne(at, cell[a]), enters_at_t));
    out.cell[a] =
        hn::IfThenElse(exits, hn::Add(lo[a], c.side), hn::IfThenElse(moving, at, cell[a]));
    const MI in_mask = hn::Or(exits, hn::And(moving, joins));
    out.mask = hn::Or(out.mask, hn::IfThenElseZero(in_mask, hn::Set(di, 1 << a)));
  }
  return out;
}

// Lane groups stepped together: one group's step is a chain of dependent gathers and float
// operations, and the core overlaps the chains of independent groups when their phases sit
// next to each other in the instruction stream.
constexpr int kGroups = 2;

// The step's outcome written back to `s`; returns the lanes whose ray ended, on a solid cell
// (the hit) or outside the grid.
HWY_INLINE MI commitStep(StreamLanes& s, VI* cell, const Cubes& c, const Leave& next,
                         const VI* last, VI max_steps) {
  const DF df;
  const DI di;
  const MI active = hn::Gt(hn::Load(di, s.ray), hn::Set(di, -1));
  // A solid lane keeps its cell: it is the hit.
  const MI moves = hn::AndNot(c.solid, active);
  MI outside = hn::FirstN(di, 0);
  for (int a = 0; a < 3; ++a) {
    cell[a] = hn::IfThenElse(moves, next.cell[a], cell[a]);
    hn::Store(cell[a], di, s.cell[a]);
    const VI real = hn::Xor(cell[a], hn::Load(di, s.flip[a]));
    outside = hn::Or(outside, hn::Or(hn::Lt(real, hn::Zero(di)), hn::Gt(real, last[a])));
  }
  hn::Store(hn::IfThenElse(hn::RebindMask(df, moves), next.t, hn::Load(df, s.t)), df, s.t);
  hn::Store(hn::IfThenElse(moves, next.mask, hn::Load(di, s.mask)), di, s.mask);
  const VI steps = hn::Add(hn::Load(di, s.steps), hn::IfThenElseZero(moves, hn::Set(di, 1)));
  hn::Store(steps, di, s.steps);
  hn::Store(hn::VecFromMask(di, c.solid), di, s.solid);
  hn::Store(c.base, di, s.base);
  RDM_CHECK(hn::AllFalse(di, hn::And(active, hn::Gt(steps, max_steps))));
  return hn::And(active, hn::Or(c.solid, outside));
}

// One step of every lane of every group, phase by phase across the groups.
HWY_INLINE void stepGroups(const VoxelWorld& world, const int32_t* occupancy, const VI* last,
                           VI max_steps, StreamLanes* groups, MI* done) {
  const DI di;
  VI cell[kGroups][3];
  Cubes c[kGroups];
  Leave next[kGroups];
  for (int g = 0; g < kGroups; ++g) {
    for (int a = 0; a < 3; ++a) cell[g][a] = hn::Load(di, groups[g].cell[a]);
  }
  for (int g = 0; g < kGroups; ++g) {
    const VI real[3] = {hn::Xor(cell[g][0], hn::Load(di, groups[g].flip[0])),
                        hn::Xor(cell[g][1], hn::Load(di, groups[g].flip[1])),
                        hn::Xor(cell[g][2], hn::Load(di, groups[g].flip[2]))};
    c[g] = classify(world, occupancy, real);
  }
  for (int g = 0; g < kGroups; ++g) next[g] = leave(groups[g], cell[g], c[g]);
  for (int g = 0; g < kGroups; ++g)
    done[g] = commitStep(groups[g], cell[g], c[g], next[g], last, max_steps);
}

static_assert(sizeof(FloatRay) == 9 * sizeof(float), "rays are gathered as o, d, inv");

// Lane-wise blend of `fresh` into the array `at` on the lanes of `m`.
template <class D, class V, class M, typename T>
HWY_INLINE void storeLanes(D d, M m, V fresh, T* at) {
  hn::Store(hn::IfThenElse(m, fresh, hn::Load(d, at)), d, at);
}

// Starts the rays rays[index] on the lanes of `want` as startWalk does (the latest near-plane
// time of the grid, its tie mask, the other axes' cells at that time), in walk coordinates.
// Returns the lanes whose ray walks: regular, and meeting the grid.
HWY_INLINE MI startLanes(const FloatRay* rays, VI index, MI want, const VI* extent,
                         StreamLanes& s) {
  const DF df;
  const DI di;
  const float* base = reinterpret_cast<const float*>(rays);
  const VI first = hn::Mul(hn::IfThenElseZero(want, index), hn::Set(di, 9));
  VF o[3], d[3], inv[3], t_near[3];
  VI start[3], near[3], flips[3];
  MI moving[3], regular = want, any_moving = hn::FirstN(di, 0);
  VF t_enter = hn::Zero(df), t_exit = hn::Set(df, FloatRay::never());
  for (int a = 0; a < 3; ++a) {
    const VF ray_o = hn::GatherIndex(df, base, hn::Add(first, hn::Set(di, a)));
    const VF ray_d = hn::GatherIndex(df, base, hn::Add(first, hn::Set(di, 3 + a)));
    const VF ray_inv = hn::GatherIndex(df, base, hn::Add(first, hn::Set(di, 6 + a)));
    const MI flip = hn::RebindMask(di, hn::Lt(ray_d, hn::Zero(df)));
    const auto flip_f = hn::RebindMask(df, flip);
    moving[a] = hn::RebindMask(di, hn::Ne(ray_d, hn::Zero(df)));
    // FloatRay::regular, lane-wise (NaN fails every comparison).
    const VF abs_inv = hn::Abs(ray_inv);
    const MI inv_ok = hn::RebindMask(
        di, hn::And(hn::Le(abs_inv, hn::Set(df, 1e20f)), hn::Ge(abs_inv, hn::Set(df, 1e-20f))));
    const MI o_ok = hn::RebindMask(di, hn::Le(hn::Abs(ray_o), hn::Set(df, 1048576.0f)));
    regular = hn::And(regular, hn::And(o_ok, hn::Or(hn::Not(moving[a]), inv_ok)));
    any_moving = hn::Or(any_moving, moving[a]);
    o[a] = hn::IfThenElse(flip_f, hn::Neg(ray_o), ray_o);
    d[a] = hn::IfThenElse(flip_f, hn::Neg(ray_d), ray_d);
    inv[a] = hn::IfThenElse(flip_f, hn::Neg(ray_inv), ray_inv);
    // walkStartCell, mirrored: floor(-o) = ~(ceil(o) - 1).
    start[a] = hn::ConvertTo(di, hn::Floor(o[a]));
    near[a] = hn::IfThenElseZero(flip, hn::Neg(extent[a]));
    const auto moving_f = hn::RebindMask(df, moving[a]);
    t_near[a] = hn::IfThenElse(moving_f, hn::Mul(hn::Sub(hn::ConvertTo(df, near[a]), o[a]), inv[a]),
                               hn::Set(df, -FloatRay::never()));
    const VF t_far = hn::Mul(hn::Sub(hn::ConvertTo(df, hn::Add(near[a], extent[a])), o[a]), inv[a]);
    t_enter = hn::Max(t_enter, t_near[a]);
    t_exit = hn::Min(t_exit, hn::IfThenElse(moving_f, t_far, hn::Set(df, FloatRay::never())));
    flips[a] = hn::VecFromMask(di, flip);
  }
  const MI entering = hn::RebindMask(di, hn::Gt(t_enter, hn::Zero(df)));
  MI walking = hn::And(hn::And(regular, any_moving), hn::RebindMask(di, hn::Lt(t_enter, t_exit)));
  VI mask = hn::Zero(di), cell[3];
  for (int a = 0; a < 3; ++a) {
    const MI crossed =
        hn::And(hn::And(entering, moving[a]), hn::RebindMask(di, hn::Eq(t_near[a], t_enter)));
    const MI at_entry = hn::AndNot(crossed, hn::And(entering, moving[a]));
    const VI hi = hn::Sub(hn::Add(near[a], extent[a]), hn::Set(di, 1));
    const VI entry_cell = cellAt(o[a], d[a], inv[a], t_enter, near[a], hi);
    cell[a] = hn::IfThenElse(crossed, near[a], hn::IfThenElse(at_entry, entry_cell, start[a]));
    // Any other axis keeps its start cell, which must lie in the grid.
    const VI real = hn::Xor(start[a], flips[a]);
    const MI inside = hn::And(hn::Gt(real, hn::Set(di, -1)), hn::Lt(real, extent[a]));
    walking = hn::And(walking, hn::Or(hn::Or(crossed, at_entry), inside));
    mask = hn::Or(mask, hn::IfThenElseZero(crossed, hn::Set(di, 1 << a)));
  }
  const auto walking_f = hn::RebindMask(df, walking);
  for (int a = 0; a < 3; ++a) {
    storeLanes(df, walking_f, o[a], s.o[a]);
    storeLanes(df, walking_f, d[a], s.d[a]);
    storeLanes(df, walking_f, inv[a], s.inv[a]);
    const auto moving_f = hn::RebindMask(df, moving[a]);
    storeLanes(df, walking_f, hn::IfThenElse(moving_f, o[a], hn::Set(df, -FloatRay::never())),
               s.o_times[a]);
    storeLanes(df, walking_f, hn::IfThenElse(moving_f, inv[a], hn::Set(df, FloatRay::never())),
               s.inv_times[a]);
    storeLanes(di, walking, cell[a], s.cell[a]);
    storeLanes(di, walking, flips[a], s.flip[a]);
  }
  storeLanes(df, walking_f, t_enter, s.t);
  storeLanes(di, walking, mask, s.mask);
  storeLanes(di, walking, hn::Zero(di), s.steps);
  storeLanes(di, walking, index, s.ray);
  return walking;
}

HWY_INLINE uint64_t maskBits(MI m) {
  uint8_t bytes[8] = {};
  hn::StoreMaskBits(DI(), m, bytes);
  uint64_t bits;
  std::memcpy(&bits, bytes, sizeof(bits));
  return bits;
}

// The stream's next rays, started a vector at a time (startLanes) and handed to lanes one by
// one as they free up; rays that do not walk are settled as they are started.
class StartBatches {
 public:
  StartBatches(StreamIo& io, const FloatRay* rays, size_t n, const VI* extent)
      : io_(io), rays_(rays), n_(n), extent_(extent) {}

  // Moves the next walking ray into `lane` of `s`; parks the lane when the stream is done.
  void refill(StreamLanes& s, size_t lane) {
    while (ready_ == 0 && next_ < n_) startBatch();
    if (ready_ == 0) return park(s, lane);
    const size_t j = size_t(__builtin_ctzll(ready_));
    ready_ &= ready_ - 1;
    for (int a = 0; a < 3; ++a) {
      s.o[a][lane] = batch_.o[a][j], s.d[a][lane] = batch_.d[a][j];
      s.inv[a][lane] = batch_.inv[a][j], s.o_times[a][lane] = batch_.o_times[a][j];
      s.inv_times[a][lane] = batch_.inv_times[a][j], s.flip[a][lane] = batch_.flip[a][j];
      s.cell[a][lane] = batch_.cell[a][j];
    }
    s.t[lane] = batch_.t[j], s.mask[lane] = batch_.mask[j], s.steps[lane] = 0;
    s.ray[lane] = batch_.ray[j];
  }

 private:
  void startBatch() {
    const DI di;
    const size_t count = std::min(n_ - next_, hn::Lanes(di));
    const MI want = hn::FirstN(di, count);
    const VI index = hn::Add(hn::Set(di, int32_t(next_)), hn::Iota(di, 0));
    const MI walking = startLanes(rays_, index, want, extent_, batch_);
    for (uint64_t bits = maskBits(hn::AndNot(walking, want)); bits != 0; bits &= bits - 1)
      io_.settle(next_ + size_t(__builtin_ctzll(bits)));
    ready_ = maskBits(walking);
    next_ += count;
  }
  // A lane without a ray: its cell (0, 0, 0) keeps every lookup in bounds.
  static void park(StreamLanes& s, size_t lane) {
    for (int a = 0; a < 3; ++a) {
      s.o[a][lane] = s.o_times[a][lane] = 0.5f;
      s.d[a][lane] = s.inv[a][lane] = s.inv_times[a][lane] = 1.0f;
      s.cell[a][lane] = s.flip[a][lane] = 0;
    }
    s.t[lane] = 0.0f, s.mask[lane] = 0, s.steps[lane] = 0, s.ray[lane] = -1;
  }

  StreamIo& io_;
  const FloatRay* rays_;
  size_t n_;
  const VI* extent_;
  StreamLanes batch_;
  uint64_t ready_ = 0;  // lanes of batch_ whose ray walks and is not handed out yet
  size_t next_ = 0;
};

void traceStream(const VoxelWorld& world, const FloatRay* rays, TraceHit* hits, float* t_hits,
                 size_t n) {
  const DI di;
  static const BrickMasks kNoBlocks{};
  const int32_t* occupancy = reinterpret_cast<const int32_t*>(
      world.occupancy.empty() ? &kNoBlocks : world.occupancy.data());
  const glm::ivec3 e = world.voxelExtent();
  const VI extent[3] = {hn::Set(di, e.x), hn::Set(di, e.y), hn::Set(di, e.z)};
  const VI last[3] = {hn::Set(di, e.x - 1), hn::Set(di, e.y - 1), hn::Set(di, e.z - 1)};
  // Every step enters a new cell on some axis, and cells only advance.
  const VI max_steps = hn::Set(di, e.x + e.y + e.z + 8);
  StreamIo io(world, {rays, n}, {hits, n}, {t_hits, n});
  StartBatches starts(io, rays, n, extent);
  StreamLanes groups[kGroups];
  for (StreamLanes& s : groups) {
    for (size_t lane = 0; lane < hn::Lanes(di); ++lane) starts.refill(s, lane);
  }
  for (;;) {
    bool any = false;
    for (const StreamLanes& s : groups)
      any = any || !hn::AllFalse(di, hn::Gt(hn::Load(di, s.ray), hn::Set(di, -1)));
    if (!any) break;
    MI done[kGroups];
    stepGroups(world, occupancy, last, max_steps, groups, done);
    for (int g = 0; g < kGroups; ++g) {
      for (uint64_t bits = maskBits(done[g]); bits != 0; bits &= bits - 1) {
        const size_t lane = size_t(__builtin_ctzll(bits));
        io.finish(groups[g], lane);
        starts.refill(groups[g], lane);
      }
    }
  }
  io.resolvePalettes();
}

int streamLanes() {
  return int(hn::Lanes(DF()));
}
const char* streamTarget() {
  return hwy::TargetName(HWY_TARGET);
}

}  // namespace HWY_NAMESPACE
}  // namespace rdm
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace rdm {

HWY_EXPORT(traceStream);
HWY_EXPORT(streamLanes);
HWY_EXPORT(streamTarget);

void traceVoxelStream(const VoxelWorld& world, std::span<const FloatRay> rays,
                      std::span<TraceHit> hits, std::span<float> t_hits) {
  RDM_CHECK(hits.size() == rays.size() && t_hits.size() == rays.size());
  // Lanes index rays and their floats with 32-bit integers (9 floats a ray).
  constexpr size_t kChunk = size_t(1) << 24;
  for (size_t first = 0; first < rays.size(); first += kChunk) {
    const size_t n = std::min(kChunk, rays.size() - first);
    HWY_DYNAMIC_DISPATCH(traceStream)
    (world, rays.data() + first, hits.data() + first, t_hits.data() + first, n);
  }
}

int voxelStreamLanes() {
  return HWY_DYNAMIC_DISPATCH(streamLanes)();
}

const char* voxelStreamTarget() {
  return HWY_DYNAMIC_DISPATCH(streamTarget)();
}

}  // namespace rdm
#endif  // HWY_ONCE
