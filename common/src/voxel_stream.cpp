// traceVoxelStream: rdm_walk.h's walkLeave on every lane of a Highway vector. Compiled once
// per x86 target (foreach_target) and picked at run time. Bit identity with walkLeave needs
// the same float operations per lane: sub, mul and add without contraction (CMake sets
// -ffp-contract=off), floor and ceil exact.
#include "rdm/voxel_stream.h"

#include <cstring>

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "voxel_stream.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include "rdm/check.h"
#include "rdm/rdm_shared_cpp.h"

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
constexpr int kOccupancyWords = int(sizeof(BrickMasks) / 4);
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
  alignas(64) int32_t block[kLanes];  // the cell's block, at the last step
};

// The per-ray work a lane does on its own: starting a ray and writing its result.
class StreamIo {
 public:
  StreamIo(const VoxelWorld& world, std::span<const FloatRay> rays, std::span<TraceHit> hits,
           std::span<float> t_hits)
      : world_(world), rays_(rays), hits_(hits), t_hits_(t_hits), extent_(world.voxelExtent()) {}

  // Loads the next ray that needs walking into `lane`; parks the lane when none is left.
  void refill(StreamLanes& s, size_t lane) {
    while (next_ < rays_.size()) {
      if (start(s, lane, next_++)) return;
    }
    park(s, lane);
  }
  // Writes the result of the ray in `lane`. The hit voxel's palette byte is likely a cache
  // miss (4 KiB per block): it is prefetched here and read in resolvePalettes.
  void finish(StreamLanes& s, size_t lane) {
    const size_t i = size_t(s.ray[lane]);
    TraceHit& hit = hits_[i];
    hit = TraceHit();
    hit.steps = s.steps[lane];
    --walking_;
    if (!s.solid[lane]) return;
    const glm::ivec3 v(s.cell[0][lane] ^ s.flip[0][lane], s.cell[1][lane] ^ s.flip[1][lane],
                       s.cell[2][lane] ^ s.flip[2][lane]);
    hit.hit = true, hit.voxel = v;
    hit.axis = s.mask[lane] == 0 ? -1 : shared::entryAxis(s.mask[lane], rays_[i].d);
    hit.started_solid = hit.axis < 0;
    t_hits_[i] = s.t[lane];
    const glm::ivec3 l = v & 15;
    const uint8_t* palette =
        &world_.blocks[size_t(s.block[lane])].voxels[l.x + 16 * l.y + 256 * l.z];
    __builtin_prefetch(palette);
    pending_[pending_count_++] = {&hit, palette};
    if (pending_count_ == kPending) resolvePalettes();
  }
  void resolvePalettes() {
    for (int k = 0; k < pending_count_; ++k) pending_[k].hit->palette = *pending_[k].palette;
    pending_count_ = 0;
  }
  int walking() const { return walking_; }

 private:
  bool start(StreamLanes& s, size_t lane, size_t i) {
    const FloatRay& ray = rays_[i];
    if (!ray.regular()) {
      hits_[i] = detail::referenceWalk(world_, ray, t_hits_[i], NoSlotVisitor());
      return false;
    }
    glm::ivec3 cell;
    int mask = 0;
    float t = 0.0f;
    bool inside = true;
    for (int a = 0; a < 3; ++a) {
      cell[a] = ray.startCell(a);
      inside = inside && cell[a] >= 0 && cell[a] < extent_[a];
    }
    if (!inside && !detail::startWalk(ray, extent_, cell, mask, t)) {
      hits_[i] = TraceHit();
      return false;
    }
    for (int a = 0; a < 3; ++a) {
      const bool moving = ray.moving(a), mirrored = ray.d[a] < 0.0f;
      const float sign = mirrored ? -1.0f : 1.0f;
      s.o[a][lane] = sign * ray.o[a], s.d[a][lane] = sign * ray.d[a];
      s.inv[a][lane] = sign * ray.inv[a];
      s.o_times[a][lane] = moving ? s.o[a][lane] : -FloatRay::never();
      s.inv_times[a][lane] = moving ? s.inv[a][lane] : FloatRay::never();
      s.flip[a][lane] = mirrored ? -1 : 0;
      s.cell[a][lane] = mirrored ? ~cell[a] : cell[a];
    }
    s.t[lane] = t, s.mask[lane] = mask, s.steps[lane] = 0, s.ray[lane] = int32_t(i);
    ++walking_;
    return true;
  }
  static void park(StreamLanes& s, size_t lane) {
    for (int a = 0; a < 3; ++a) {
      s.o[a][lane] = s.o_times[a][lane] = 0.5f;
      s.d[a][lane] = s.inv[a][lane] = s.inv_times[a][lane] = 1.0f;
      s.cell[a][lane] = s.flip[a][lane] = 0;
    }
    s.t[lane] = 0.0f, s.mask[lane] = 0, s.steps[lane] = 0, s.ray[lane] = -1;
  }

  const VoxelWorld& world_;
  std::span<const FloatRay> rays_;
  std::span<TraceHit> hits_;
  std::span<float> t_hits_;
  glm::ivec3 extent_;
  size_t next_ = 0;
  int walking_ = 0;  // lanes holding a ray
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

// boundaryTime of integer planes.
HWY_INLINE VF planeTime(VI plane, VF o, VF inv) {
  return hn::Mul(hn::Sub(hn::ConvertTo(DF(), plane), o), inv);
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
  VI low, side, block;
  VI grain;  // 15 when the cube is a slot or more: a mask joins only at slot planes
  MI slot_empty, solid;
};

HWY_INLINE Cubes classify(const VoxelWorld& world, const int32_t* occupancy, const VI* cell) {
  const DI di;
  const VI sx = hn::ShiftRight<4>(cell[0]), sy = hn::ShiftRight<4>(cell[1]);
  const VI sz = hn::ShiftRight<4>(cell[2]);
  const VI slot = hn::Add(
      sx, hn::Mul(hn::Set(di, world.size.x), hn::Add(sy, hn::Mul(hn::Set(di, world.size.y), sz))));
  const VI block = hn::GatherIndex(di, world.slots.data(), slot);
  const MI slot_empty = hn::Lt(block, hn::Zero(di));
  const VI pair =
      hn::Add(hn::ShiftRight<1>(sx),
              hn::Mul(hn::Set(di, world.pair_size.x),
                      hn::Add(hn::ShiftRight<1>(sy),
                              hn::Mul(hn::Set(di, world.pair_size.y), hn::ShiftRight<1>(sz)))));
  const MI pair_empty = hn::And(
      slot_empty, hn::Ne(hn::GatherIndex(di, world.empty_pairs.data(), pair), hn::Zero(di)));
  const VI base = hn::Mul(hn::Max(block, hn::Zero(di)), hn::Set(di, kOccupancyWords));
  const VI m3 = hn::Set(di, 3);
  const VI bx = hn::And(hn::ShiftRight<2>(cell[0]), m3),
           by = hn::And(hn::ShiftRight<2>(cell[1]), m3);
  const VI bz = hn::And(hn::ShiftRight<2>(cell[2]), m3);
  const VI brick = hn::Or(bx, hn::Or(hn::ShiftLeft<2>(by), hn::ShiftLeft<4>(bz)));
  const VI bricks_word = hn::GatherIndex(di, occupancy, hn::Add(base, hn::ShiftRight<5>(brick)));
  const VI m31 = hn::Set(di, 31);
  const MI brick_full = hn::AndNot(slot_empty, bitSet(bricks_word, hn::And(brick, m31)));
  const VI vx = hn::And(cell[0], m3), vy = hn::And(cell[1], m3), vz = hn::And(cell[2], m3);
  const VI voxel = hn::Or(vx, hn::Or(hn::ShiftLeft<2>(vy), hn::ShiftLeft<4>(vz)));
  const VI word = hn::Add(hn::Add(base, hn::Set(di, 2)),
                          hn::Add(hn::ShiftLeft<1>(brick), hn::ShiftRight<5>(voxel)));
  const VI voxel_word = hn::GatherIndex(di, occupancy, word);
  Cubes c;
  c.slot_empty = slot_empty;
  c.block = block;
  c.solid = hn::And(brick_full, bitSet(voxel_word, hn::And(voxel, m31)));
  c.low = hn::IfThenElse(slot_empty, hn::IfThenElse(pair_empty, hn::Set(di, -32), hn::Set(di, -16)),
                         hn::IfThenElse(brick_full, hn::Set(di, -1), hn::Set(di, -4)));
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
    // In a brick or at a voxel, an axis that crosses a voxel plane exactly at t joins the
    // mask, as a voxel step would.
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
  hn::Store(c.block, di, s.block);
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

void traceStream(const VoxelWorld& world, const FloatRay* rays, TraceHit* hits, float* t_hits,
                 size_t n) {
  const DI di;
  const size_t lanes = hn::Lanes(di);
  static const BrickMasks kNoBlocks{};
  const int32_t* occupancy = reinterpret_cast<const int32_t*>(
      world.occupancy.empty() ? &kNoBlocks : world.occupancy.data());
  const glm::ivec3 e = world.voxelExtent();
  const VI last[3] = {hn::Set(di, e.x - 1), hn::Set(di, e.y - 1), hn::Set(di, e.z - 1)};
  // Every step enters a new cell on some axis, and cells only advance.
  const VI max_steps = hn::Set(di, e.x + e.y + e.z + 8);
  StreamIo io(world, {rays, n}, {hits, n}, {t_hits, n});
  StreamLanes groups[kGroups];
  for (StreamLanes& s : groups) {
    for (size_t lane = 0; lane < lanes; ++lane) io.refill(s, lane);
  }
  while (io.walking() > 0) {
    MI done[kGroups];
    stepGroups(world, occupancy, last, max_steps, groups, done);
    for (int g = 0; g < kGroups; ++g) {
      uint8_t bits[8] = {};
      hn::StoreMaskBits(di, done[g], bits);
      uint64_t done_lanes;
      std::memcpy(&done_lanes, bits, sizeof(done_lanes));
      for (; done_lanes != 0; done_lanes &= done_lanes - 1) {
        const size_t lane = size_t(__builtin_ctzll(done_lanes));
        io.finish(groups[g], lane);
        io.refill(groups[g], lane);
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
  HWY_DYNAMIC_DISPATCH(traceStream)(world, rays.data(), hits.data(), t_hits.data(), rays.size());
}

int voxelStreamLanes() {
  return HWY_DYNAMIC_DISPATCH(streamLanes)();
}

const char* voxelStreamTarget() {
  return HWY_DYNAMIC_DISPATCH(streamTarget)();
}

}  // namespace rdm
#endif  // HWY_ONCE
