#include "rdm/bake/bake.h"
#include "rdm/bake/bake_stats.h"
#include "rdm/bake/slot_set.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "face_map_cache.h"
#include "rdm/base/parallel.h"
#include "rdm/trace/integrator.h"
#include "rdm/trace/traversal.h"
#include "rdm/transport/rdm_shared_cpp.h"
#include "rdm/transport/sobol.h"

namespace rdm {
namespace {

using glm::ivec2;
using glm::ivec3;
using glm::vec2;
using glm::vec3;

constexpr int kTile = 64;  // work units cover at most 64 x 64 texels of one face

using Unit = BakeUnit;

// Grids up to this many slots record slot sets as bitsets (2 x 128 KiB per unit at most).
constexpr size_t kMaxBitsetSlots = size_t(1) << 20;

struct UnitSets {
  std::vector<uint32_t> full, first;
  std::vector<uint64_t> full_bits, first_bits;  // while a unit runs, when the grid is small
  bool smooth = false;
  uint32_t max_samples = 0;  // per unit: units of one RDM run concurrently
};

struct Shared {
  const VoxelWorld& world;
  const BakeSettings& settings;
  const BakeOptions& options;
  std::vector<RdmData>& out;
  FaceMapCache& maps;
};

void appendBits(const std::vector<uint64_t>& bits, std::vector<uint32_t>& out) {
  for (size_t w = 0; w < bits.size(); ++w) {
    for (uint64_t b = bits[w]; b != 0; b &= b - 1)
      out.push_back(uint32_t(w * 64 + size_t(__builtin_ctzll(b))));
  }
}

int mapLevel(const Shared& s, const glm::ivec3& slot) {
  return radianceMapLevel(s.world, s.settings, slot);
}

FaceMapCache::Key mapKey(const Shared& s, const glm::ivec3& slot, int face) {
  return {uint32_t(s.world.slotLinear(slot)), face};
}

// Bakes the texels of one face: of an RDM, or (level 0 estimator, no RDM) of a radiance map.
template <bool kSun, bool kEmitters, bool kRecord>
class FaceBaker {
 public:
  FaceBaker(const Shared& s, const glm::ivec3& slot, int level, int size, int face,
            PathStats& stats, UnitSets& sets)
      : s_(s),
        slot_(slot),
        level_(level),
        face_(face),
        stats_(stats),
        sets_(sets),
        S_(size),
        frame_(detail::faceFrame(face)),
        origin_(vec3(slot * 16 + ivec3(8) + 8 * shared::faceNormal(face))) {}

  void bakeTile(RdmData& rdm, const Unit& u) {
    for (int j = u.y0; j < u.y1; ++j) {
      prefetchRow(j, u.x0, u.x1);
      for (int i = u.x0; i < u.x1; ++i) {
        uint32_t n = 0;
        SampleEstimator e = estimateTexel(i, j, n);
        store(rdm, i, j, e.mean(), e.stderror(), n);
      }
    }
  }

  // Level 7: S^2 spp cosine paths (texel keys), one mean for the whole face.
  void bakeDiffuseFace(RdmData& rdm) {
    SampleEstimator e;
    uint32_t n = 0, target = uint32_t(s_.settings.spp);
    while (true) {
      for (int j = 0; j < S_; ++j) {
        if (n == 0) prefetchDiffuseRow(j);
        for (int i = 0; i < S_; ++i) {
          for (uint32_t k = n; k < target; ++k) e.add(diffuseSample(i, j, k), 1.0f);
        }
      }
      n = target;
      if (!refine(e, n, target)) break;
    }
    for (int j = 0; j < S_; ++j)
      for (int i = 0; i < S_; ++i) store(rdm, i, j, e.mean(), e.stderror(), n);
  }

  // The face's radiance map: the level 0 estimator at this baker's size, and level 7 from the
  // same samples, each weighted by its cosine solid angle (docs/spec.md section 3.1).
  void traceMap(FaceMap& out) {
    FaceMapBuilder builder(S_);
    for (int j = 0; j < S_; ++j) {
      prefetchRow(j, 0, S_);
      for (int i = 0; i < S_; ++i) {
        uint32_t n = 0;
        CosineSums cosine;
        SampleEstimator e = estimateTexel(i, j, n, &cosine);
        builder.setTexel(i, j, e, n, cosine);
      }
    }
    builder.finish(out);
  }

  // The RDM's texels from the face's map: level 0 is the map, rough levels its kernels.
  void bakeFromMap(RdmData& rdm, const FaceMap& m) {
    const FaceMapDerivation derive(m, rdm.id.level, S_);
    for (int j = 0; j < S_; ++j)
      for (int i = 0; i < S_; ++i) {
        glm::vec3 mean, var;
        derive.texel(i, j, mean, var);
        store(rdm, i, j, glm::dvec3(mean), glm::sqrt(glm::dvec3(var)), m.max_samples);
      }
  }

 private:
  uint32_t key(int i, int j, uint32_t sample) const {
    uint32_t texel = uint32_t(face_ * S_ * S_ + j * S_ + i);
    return shared::pathKey(s_.settings.seed, slotKey(slot_), uint32_t(level_), texel, sample);
  }
  vec3 trace(const vec3& dir, uint32_t path_key) {
    if constexpr (kRecord) {
      if (!sets_.full_bits.empty()) {
        SlotBitRecorder rec{sets_.full_bits.data(), sets_.first_bits.data()};
        vec3 l = tracePath<kSun, kEmitters>(s_.world, s_.settings.max_bounces, origin_, dir,
                                            path_key, PathOrigin::kRdmFace, stats_, rec);
        sets_.smooth = sets_.smooth || rec.smooth_vertex;
        return l;
      }
      SlotRecorder rec{&sets_.full, &sets_.first};
      vec3 l = tracePath<kSun, kEmitters>(s_.world, s_.settings.max_bounces, origin_, dir, path_key,
                                          PathOrigin::kRdmFace, stats_, rec);
      sets_.smooth = sets_.smooth || rec.smooth_vertex;
      if (sets_.full.size() > 4096) sortUniqueSlots(sets_.full), sortUniqueSlots(sets_.first);
      return l;
    } else {
      return tracePath<kSun, kEmitters>(s_.world, s_.settings.max_bounces, origin_, dir, path_key,
                                        PathOrigin::kRdmFace, stats_, NoRecorder(),
                                        first_.take(origin_, dir));
    }
  }
  // The first segments of the first spp samples of texels [x0, x1) of row j, traced as one
  // stream; trace() takes them in order. Recording paths trace their own (they visit slots).
  void prefetchRow(int j, int x0, int x1) {
    if constexpr (kRecord) return;
    first_.clear(), draws_.clear();
    draws_row_ = j, draws_x0_ = x0;
    for (int i = x0; i < x1; ++i) {
      const vec3 w = centralDirection(i, j);
      for (uint32_t sample = 0; sample < uint32_t(s_.settings.spp); ++sample) {
        draws_.push_back(drawSample(i, j, w, sample));
        if (draws_.back().o.traced) first_.add(origin_, draws_.back().o.dir);
      }
    }
    first_.trace(s_.world);
  }
  void prefetchDiffuseRow(int j) {
    if constexpr (kRecord) return;
    first_.clear();
    for (int i = 0; i < S_; ++i) {
      for (uint32_t k = 0; k < uint32_t(s_.settings.spp); ++k) {
        const shared::OriginDraw o = diffuseDraw(key(i, j, k));
        if (o.traced) first_.add(origin_, o.dir);
      }
    }
    first_.trace(s_.world);
  }
  shared::OriginDraw diffuseDraw(uint32_t k) const {
    return shared::originCosineDraw(shFrame(), shared::randomUniform(k, 0, shared::kDimOrigin0),
                                    shared::randomUniform(k, 0, shared::kDimOrigin1));
  }
  vec3 diffuseSample(int i, int j, uint32_t sample) {
    const uint32_t k = key(i, j, sample);
    const shared::OriginDraw o = diffuseDraw(k);
    return o.traced ? trace(o.dir, k) : vec3(0.0f);
  }
  // Doubles the sample count while the target error is not met (target-error mode).
  bool refine(const SampleEstimator& e, uint32_t n, uint32_t& target) const {
    if (s_.options.target_error <= 0.0) return false;
    uint32_t cap = uint32_t(s_.settings.spp) * uint32_t(std::max(1, s_.options.max_spp_factor));
    if (n >= cap || e.relativeError() < s_.options.target_error) return false;
    target = std::min(cap, n * 2);
    return true;
  }
  // Level 0: uniform over the texel's hemi-oct footprint. Rough levels: GGX half vectors
  // around the central direction, reflected, weighted by w.l (prefiltered importance sampling).
  // `cosine` (level 0 only) also sums each sample weighted by cos(theta) dw / du dv.
  struct SampleDraw {
    shared::OriginDraw o;
    float u0, u1;
  };
  SampleDraw drawSample(int i, int j, const vec3& w, uint32_t sample) const {
    const uint32_t k = key(i, j, sample);
    float u0 = shared::randomUniform(k, 0, shared::kDimOrigin0);
    float u1 = shared::randomUniform(k, 0, shared::kDimOrigin1);
    if (level_ == 0 && s_.settings.estimator == Estimator::kPrefiltered) {
      const Point2 p = owenSobol2(sample, key(i, j, 0));  // stratified over the footprint
      u0 = p.u0, u1 = p.u1;
    }
    if (level_ == 0) return {shared::originTexelDraw(shFrame(), i, j, S_, u0, u1), u0, u1};
    return {shared::originLobeDraw(shFrame(), w, shared::roughnessAlpha(level_), u0, u1), u0, u1};
  }
  void addSample(int i, int j, const vec3& w, uint32_t sample, SampleEstimator& e,
                 CosineSums* cosine) {
    const uint32_t spp = uint32_t(s_.settings.spp);
    const size_t cached = size_t(i - draws_x0_) * spp + sample;
    const SampleDraw d = j == draws_row_ && i >= draws_x0_ && sample < spp && cached < draws_.size()
                             ? draws_[cached]
                             : drawSample(i, j, w, sample);
    const uint32_t k = key(i, j, sample);
    if (level_ == 0) {
      const vec3 radiance = d.o.traced ? trace(d.o.dir, k) : vec3(0.0f);
      e.add(radiance, d.o.weight);
      if (cosine) cosine->add(shared::texelFootprintPoint(i, j, S_, d.u0, d.u1), radiance);
      return;
    }
    if (d.o.traced) e.add(trace(d.o.dir, k), d.o.weight);
  }
  vec3 centralDirection(int i, int j) const {
    return glm::normalize(frame_.toWorld(vec3(shared::texelCentralDirection(i, j, S_))));
  }
  SampleEstimator estimateTexel(int i, int j, uint32_t& n, CosineSums* cosine = nullptr) {
    const vec3 w = centralDirection(i, j);
    SampleEstimator e;
    uint32_t target = uint32_t(s_.settings.spp);
    n = 0;
    while (true) {
      for (uint32_t sample = n; sample < target; ++sample) addSample(i, j, w, sample, e, cosine);
      n = target;
      if (!refine(e, n, target)) break;
    }
    return e;
  }
  void store(RdmData& rdm, int i, int j, const glm::dvec3& mean, const glm::dvec3& err,
             uint32_t samples) {
    const ivec2 px = shared::rdmTexelPixel(0, 0, S_, face_, i, j);
    const ivec3 d = shared::texelCentralDirection(i, j, S_);
    const ivec3 dir = d.x * shared::faceTangent(face_) + d.y * shared::faceBitangent(face_) +
                      d.z * shared::faceNormal(face_);
    storeRadiance(rdm, face_, i, j, mean, err);
    if constexpr (kRecord) {
      std::vector<uint32_t> central;  // central rays belong to both sets (docs/spec.md section 8)
      rdm.image.at(px.x, px.y, 3) = exactCentralDepth(s_.world, ivec3(origin_), dir, &central);
      sets_.first.insert(sets_.first.end(), central.begin(), central.end());
      sets_.full.insert(sets_.full.end(), central.begin(), central.end());
    } else {
      rdm.image.at(px.x, px.y, 3) = exactCentralDepth(s_.world, ivec3(origin_), dir);
    }
    sets_.max_samples = std::max(sets_.max_samples, samples);
  }

  const Shared& s_;
  const ivec3 slot_;
  const int level_;
  const int face_;
  PathStats& stats_;
  UnitSets& sets_;
  const int S_;
  const Frame frame_;
  shared::ShFrame shFrame() const { return {frame_.t, frame_.b, frame_.n}; }
  const vec3 origin_;
  FirstSegments first_;
  std::vector<SampleDraw> draws_;  // prefetchRow's draws of row draws_row_, from column draws_x0_
  int draws_row_ = -1, draws_x0_ = 0;
};

// Slot sets are recorded as bitsets over the grid while a unit runs, when the grid is small.
void startRecording(const Shared& s, UnitSets& sets) {
  if (s.world.slots.size() > kMaxBitsetSlots) return;
  sets.full_bits.assign((s.world.slots.size() + 63) / 64, 0);
  sets.first_bits.assign(sets.full_bits.size(), 0);
}
void stopRecording(UnitSets& sets) {
  if (sets.full_bits.empty()) return;
  appendBits(sets.full_bits, sets.full), appendBits(sets.first_bits, sets.first);
  // Freed, not cleared: every unit keeps its UnitSets for the session's life.
  sets.full_bits = std::vector<uint64_t>(), sets.first_bits = std::vector<uint64_t>();
}

template <bool kSun, bool kEmitters, bool kRecord>
void bakeFromFaceMap(const Shared& s, const Unit& u, int map_level, PathStats& stats,
                     UnitSets& sets) {
  RdmData& rdm = s.out[u.rdm];
  const FaceMapCache::Key key = mapKey(s, rdm.id.slot, u.face);
  const FaceMap& m = s.maps.acquire(key, [&](FaceMap& out) {
    UnitSets map_sets;
    if (kRecord) startRecording(s, map_sets);
    const int size = shared::hemisphereSize(map_level, s.settings.max_hemisphere);
    FaceBaker<kSun, kEmitters, kRecord>(s, rdm.id.slot, 0, size, u.face, stats, map_sets)
        .traceMap(out);
    stopRecording(map_sets);
    sortUniqueSlots(map_sets.full), sortUniqueSlots(map_sets.first);
    out.full_set = std::move(map_sets.full), out.first_set = std::move(map_sets.first);
    out.smooth_vertex = map_sets.smooth;
  });
  sets.full.insert(sets.full.end(), m.full_set.begin(), m.full_set.end());
  sets.first.insert(sets.first.end(), m.first_set.begin(), m.first_set.end());
  sets.smooth = sets.smooth || m.smooth_vertex;
  FaceBaker<kSun, kEmitters, kRecord>(s, rdm.id.slot, rdm.id.level, rdm.id.size, u.face, stats,
                                      sets)
      .bakeFromMap(rdm, m);
  s.maps.release(key);
}

template <bool kSun, bool kEmitters, bool kRecord>
void runUnit(const Shared& s, const Unit& u, PathStats& stats, UnitSets& sets) {
  RdmData& rdm = s.out[u.rdm];
  if (kRecord) startRecording(s, sets);
  const int map_level = mapLevel(s, rdm.id.slot);
  if (map_level >= 0) {
    bakeFromFaceMap<kSun, kEmitters, kRecord>(s, u, map_level, stats, sets);
  } else {
    FaceBaker<kSun, kEmitters, kRecord> baker(s, rdm.id.slot, rdm.id.level, rdm.id.size, u.face,
                                              stats, sets);
    if (rdm.id.level == shared::kDiffuseLevel) {
      baker.bakeDiffuseFace(rdm);
    } else {
      baker.bakeTile(rdm, u);
    }
  }
  stopRecording(sets);
}

using UnitFn = void (*)(const Shared&, const Unit&, PathStats&, UnitSets&);

template <bool kRecord>
UnitFn selectKernel(bool sun, bool emit) {
  if (sun && emit) return runUnit<true, true, kRecord>;
  if (sun) return runUnit<true, false, kRecord>;
  if (emit) return runUnit<false, true, kRecord>;
  return runUnit<false, false, kRecord>;
}

UnitFn selectKernel(const EffectSet& effects, const BakeOptions& o) {
  bool sun = effects.sun || o.all_effects, emit = effects.emitters || o.all_effects;
  return o.record_slot_sets ? selectKernel<true>(sun, emit) : selectKernel<false>(sun, emit);
}

// The sets of an RDM's units [begin, end) into `rdm`, sorted and unique; the units' sets are
// freed.
void mergeSets(std::vector<UnitSets>& sets, size_t begin, size_t end, RdmData& rdm) {
  for (size_t i = begin; i < end; ++i) {
    rdm.full_set.insert(rdm.full_set.end(), sets[i].full.begin(), sets[i].full.end());
    rdm.first_set.insert(rdm.first_set.end(), sets[i].first.begin(), sets[i].first.end());
    rdm.smooth_vertex = rdm.smooth_vertex || sets[i].smooth;
    const uint32_t max_samples = sets[i].max_samples;
    sets[i] = UnitSets();
    sets[i].max_samples = max_samples;  // finish() still reads it
  }
  sortUniqueSlots(rdm.full_set), sortUniqueSlots(rdm.first_set);
}

// Units cover tiles of a face; a face baked from its radiance map is one unit, and registers
// as one more consumer of that map.
std::vector<Unit> planUnits(const Shared& s, BakeReport& report) {
  const VoxelWorld& world = s.world;
  std::vector<RdmData>& out = s.out;
  std::vector<Unit> units;
  for (int r = 0; r < int(out.size()); ++r) {
    RdmData& rdm = out[r];
    const int S = rdm.id.size;
    for (int f = 0; f < 6; ++f) {
      rdm.skipped[f] = faceSkipped(world, rdm.id.slot, f);
      if (rdm.skipped[f]) {
        ++report.faces_skipped;
        continue;
      }
      ++report.faces_baked;
      if (mapLevel(s, rdm.id.slot) >= 0) s.maps.expect(mapKey(s, rdm.id.slot, f));
      if (rdm.id.level == shared::kDiffuseLevel || mapLevel(s, rdm.id.slot) >= 0) {
        units.push_back({r, f, 0, 0, S, S});
        continue;
      }
      for (int y = 0; y < S; y += kTile)
        for (int x = 0; x < S; x += kTile)
          units.push_back({r, f, x, y, std::min(S, x + kTile), std::min(S, y + kTile)});
    }
  }
  return units;
}

void allocateTexels(RdmData& data) {
  data.image = Image(2 * data.id.size, 3 * data.id.size, 4);
  data.stderr_rgb.assign(size_t(data.image.width) * data.image.height * 3, 0.0f);
}

}  // namespace

struct BakeSession::Impl {
  const VoxelWorld& world;
  const BakeSettings settings;
  const BakeOptions options;
  BakeResult result;
  std::vector<BakeUnit> units;
  std::vector<UnitSets> unit_sets;
  UnitFn kernel;
  FaceMapCache maps;
  Shared shared;
  // With options.on_rdm_done: texels allocated at an RDM's first unit, and the error
  // statistics of the RDMs already released.
  const bool lazy;
  std::unique_ptr<std::once_flag[]> allocated;
  std::vector<RdmErrorStats> errors;
  std::vector<uint8_t> released;
  std::vector<size_t> first_unit;  // RDM r's units are [first_unit[r], first_unit[r + 1])
  std::atomic<int> held{0}, peak_held{0};
  Impl(const VoxelWorld& w, const BakeSettings& s, const BakeOptions& o)
      : world(w),
        settings(s),
        options(o),
        kernel(nullptr),
        shared{world, settings, options, result.rdms, maps},
        lazy(bool(o.on_rdm_done)) {}
  void ensureTexels(size_t r) {
    if (!lazy) return;
    std::call_once(allocated[r], [&] {
      allocateTexels(result.rdms[r]);
      const int now = held.fetch_add(1) + 1;
      for (int peak = peak_held.load();
           now > peak && !peak_held.compare_exchange_weak(peak, now);) {
      }
    });
  }
};

BakeSession::BakeSession(const VoxelWorld& world, const BakeSettings& settings,
                         const std::vector<RdmId>& rdms, const BakeOptions& options)
    : impl_(std::make_unique<Impl>(world, settings, options)) {
  BakeResult& result = impl_->result;
  result.report.effects = sceneEffects(world);
  for (const RdmId& id : rdms) {
    RdmData data;
    data.id = id;
    if (!impl_->lazy) allocateTexels(data);
    result.rdms.push_back(std::move(data));
  }
  if (impl_->lazy) {
    impl_->allocated = std::make_unique<std::once_flag[]>(rdms.size());
    impl_->errors.resize(rdms.size());
    impl_->released.assign(rdms.size(), 0);
  }
  impl_->units = planUnits(impl_->shared, result.report);
  impl_->kernel = selectKernel(result.report.effects, impl_->options);
  impl_->unit_sets.resize(impl_->units.size());
  impl_->first_unit.assign(rdms.size() + 1, impl_->units.size());
  for (size_t i = impl_->units.size(); i-- > 0;) impl_->first_unit[impl_->units[i].rdm] = i;
  for (size_t r = rdms.size(); r-- > 0;)
    impl_->first_unit[r] = std::min(impl_->first_unit[r], impl_->first_unit[r + 1]);
}

BakeSession::~BakeSession() = default;

const std::vector<BakeUnit>& BakeSession::units() const {
  return impl_->units;
}
std::vector<RdmData>& BakeSession::rdms() {
  return impl_->result.rdms;
}

uint64_t BakeSession::runUnit(size_t i) {
  return runUnit(i, nullptr);
}

uint64_t BakeSession::runUnit(size_t i, UnitSlotSets* sets) {
  RDM_CHECK(i < impl_->units.size());
  PathStats stats;
  UnitSets& u = impl_->unit_sets[i];
  impl_->ensureTexels(size_t(impl_->units[i].rdm));
  impl_->kernel(impl_->shared, impl_->units[i], stats, u);
  if (!impl_->options.record_slot_sets) return stats.rays;
  sortUniqueSlots(u.full), sortUniqueSlots(u.first);
  if (sets) {
    sets->full = std::move(u.full), sets->first = std::move(u.first);
    sets->smooth_vertex = u.smooth;
    u.full.clear(), u.first.clear(), u.smooth = false;
  }
  return stats.rays;
}

int BakeSession::peakRdmsHeld() const {
  return impl_->lazy ? impl_->peak_held.load() : int(impl_->result.rdms.size());
}

RdmData& BakeSession::rdmTexels(size_t r) {
  RDM_CHECK(r < impl_->result.rdms.size() && (!impl_->lazy || !impl_->released[r]));
  impl_->ensureTexels(r);
  return impl_->result.rdms[r];
}

void BakeSession::releaseRdm(size_t r, const std::function<void(const RdmData&)>& done) {
  RDM_CHECK(impl_->lazy && r < impl_->result.rdms.size() && !impl_->released[r]);
  impl_->ensureTexels(r);
  RdmData& rdm = impl_->result.rdms[r];
  for (size_t i = impl_->first_unit[r]; i < impl_->first_unit[r + 1]; ++i)
    rdm.max_samples = std::max(rdm.max_samples, impl_->unit_sets[i].max_samples);
  if (impl_->options.record_slot_sets)
    mergeSets(impl_->unit_sets, impl_->first_unit[r], impl_->first_unit[r + 1], rdm);
  impl_->errors[r] = rdmErrorStats(rdm);
  done(rdm);
  rdm.image = Image();
  rdm.stderr_rgb = std::vector<float>();  // "= {}" would keep the capacity
  rdm.full_set = std::vector<uint32_t>(), rdm.first_set = std::vector<uint32_t>();
  impl_->released[r] = 1;
  impl_->held.fetch_sub(1);
}

BakeResult BakeSession::finish(double seconds, uint64_t rays, bool cancelled) {
  BakeResult& result = impl_->result;
  for (size_t i = 0; i < impl_->units.size(); ++i) {
    uint32_t& m = result.rdms[size_t(impl_->units[i].rdm)].max_samples;
    m = std::max(m, impl_->unit_sets[i].max_samples);
  }
  if (impl_->options.record_slot_sets) {
    for (size_t r = 0; r < result.rdms.size(); ++r) {
      if (impl_->lazy && impl_->released[r]) continue;  // handed to on_rdm_done
      mergeSets(impl_->unit_sets, impl_->first_unit[r], impl_->first_unit[r + 1], result.rdms[r]);
    }
  }
  result.report.rdms = int(result.rdms.size());
  result.report.rays = rays;
  result.report.cancelled = cancelled;
  result.report.seconds = seconds;
  if (impl_->lazy) {
    for (size_t r = 0; r < result.rdms.size(); ++r) {
      if (!impl_->released[r] && !result.rdms[r].image.pixels.empty())
        impl_->errors[r] = rdmErrorStats(result.rdms[r]);
    }
    summariseBake(impl_->errors, result.report);
  } else {
    summariseBake(result.rdms, result.report);
  }
  result.report.peak_rdms_held = peakRdmsHeld();
  return std::move(result);
}

namespace {

// With on_rdm_done, units run slot by slot (a slot's RDMs of every size, which share its
// radiance maps, finish together); otherwise in plan order (empty). Either order gives the
// same bits.
std::vector<size_t> unitOrder(const VoxelWorld& world, BakeSession& session,
                              const BakeOptions& options) {
  std::vector<size_t> order;
  if (!options.on_rdm_done) return order;
  const std::vector<BakeUnit>& units = session.units();
  const std::vector<RdmData>& rdms = session.rdms();
  order.resize(units.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return world.slotLinear(rdms[size_t(units[a].rdm)].id.slot) <
           world.slotLinear(rdms[size_t(units[b].rdm)].id.slot);
  });
  return order;
}

}  // namespace

BakeResult bakeRdms(const VoxelWorld& world, const BakeSettings& settings,
                    const std::vector<RdmId>& rdms, const BakeOptions& options) {
  auto start = std::chrono::steady_clock::now();
  const uint64_t setup_start = threadCpuNanoseconds();
  BakeSession session(world, settings, rdms, options);
  std::atomic<uint64_t> cpu_ns{threadCpuNanoseconds() - setup_start};  // setup, then units
  const std::vector<BakeUnit>& units = session.units();
  const size_t rdm_count = session.rdms().size();
  std::vector<std::atomic<int>> remaining(rdm_count);
  std::vector<std::atomic<uint64_t>> rdm_cpu_ns(options.rdm_cpu_seconds ? rdm_count : 0);
  uint64_t texels_total = 0;
  for (const BakeUnit& u : units) {
    remaining[u.rdm].fetch_add(1);
    texels_total += uint64_t(u.x1 - u.x0) * uint64_t(u.y1 - u.y0);
  }
  std::atomic<int> rdms_done{0};
  for (size_t r = 0; r < rdm_count; ++r) {
    if (remaining[r].load() != 0) continue;
    ++rdms_done;
    if (options.on_rdm_done) session.releaseRdm(r, options.on_rdm_done);
  }
  const std::vector<size_t> order = unitOrder(world, session, options);
  std::atomic<uint64_t> rays{0}, texels_done{0};
  std::atomic<bool> cancelled{false};
  auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  auto progress = [&] {
    if (options.on_progress)
      options.on_progress({rdms_done.load(), int(rdm_count), rays.load(), elapsed(),
                           texels_done.load(), texels_total});
  };
  progress();  // the 0 % report, before any work
  ParallelOptions parallel;
  parallel.threads = options.threads;
  if (options.on_progress) {
    parallel.on_tick = [&] {
      if (!cancelled) progress();
    };
  }
  parallelFor(units.size(), parallel, [&](size_t k) {
    const size_t i = order.empty() ? k : order[k];
    if (options.cancel && options.cancel->load()) {
      cancelled = true;
      return false;
    }
    const uint64_t unit_start = threadCpuNanoseconds();
    rays += session.runUnit(i);
    const uint64_t unit_ns = threadCpuNanoseconds() - unit_start;
    cpu_ns += unit_ns;
    const BakeUnit& u = units[i];
    if (!rdm_cpu_ns.empty()) rdm_cpu_ns[u.rdm] += unit_ns;
    texels_done += uint64_t(u.x1 - u.x0) * uint64_t(u.y1 - u.y0);
    if (remaining[u.rdm].fetch_sub(1) == 1) {
      ++rdms_done;
      if (options.on_rdm_done) session.releaseRdm(size_t(u.rdm), options.on_rdm_done);
    }
    return true;
  });
  BakeResult result = session.finish(elapsed(), rays.load(), cancelled.load());
  result.report.cpu_seconds = 1e-9 * double(cpu_ns.load());
  if (options.rdm_cpu_seconds) {
    options.rdm_cpu_seconds->clear();
    for (const auto& ns : rdm_cpu_ns) options.rdm_cpu_seconds->push_back(1e-9 * double(ns.load()));
  }
  return result;
}

std::vector<RdmId> shardRdms(const VoxelWorld& world, const BakeSettings& settings, int shard_index,
                             int shard_count) {
  std::vector<RdmId> all = listRdms(world, settings), mine;
  const size_t count = size_t(std::max(1, shard_count));
  for (size_t i = 0; i < all.size(); ++i) {
    if (int(i % count) == shard_index) mine.push_back(all[i]);
  }
  return mine;
}

BakeResult bakeScene(const VoxelWorld& world, const BakeSettings& settings,
                     const BakeOptions& options) {
  return bakeRdms(world, settings,
                  shardRdms(world, settings, options.shard_index, options.shard_count), options);
}

}  // namespace rdm
