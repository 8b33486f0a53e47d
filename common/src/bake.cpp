#include "rdm/bake.h"
#include "rdm/bake_stats.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <mutex>
#include <thread>

#include "rdm/integrator.h"
#include "rdm/rdm_shared_cpp.h"
#include "rdm/traversal.h"

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
};

void sortUnique(std::vector<uint32_t>& v) {
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
}

template <bool kSun, bool kEmitters, bool kRecord>
class FaceBaker {
 public:
  FaceBaker(const Shared& s, RdmData& rdm, int face, PathStats& stats, UnitSets& sets)
      : s_(s),
        rdm_(rdm),
        face_(face),
        stats_(stats),
        sets_(sets),
        S_(rdm.id.size),
        frame_(detail::faceFrame(face)),
        origin_(vec3(rdm.id.slot * 16 + ivec3(8) + 8 * shared::faceNormal(face))) {}

  void bakeTile(const Unit& u) {
    for (int j = u.y0; j < u.y1; ++j)
      for (int i = u.x0; i < u.x1; ++i) bakeTexel(i, j);
  }

  // Level 7: S^2 spp cosine paths (texel keys), one mean for the whole face.
  void bakeDiffuseFace() {
    SampleEstimator e;
    uint32_t n = 0, target = uint32_t(s_.settings.spp);
    while (true) {
      for (int j = 0; j < S_; ++j)
        for (int i = 0; i < S_; ++i) {
          for (uint32_t k = n; k < target; ++k) e.add(diffuseSample(i, j, k), 1.0f);
        }
      n = target;
      if (!refine(e, n, target)) break;
    }
    for (int j = 0; j < S_; ++j)
      for (int i = 0; i < S_; ++i) store(i, j, e, n);
  }

 private:
  uint32_t key(int i, int j, uint32_t sample) const {
    uint32_t texel = uint32_t(face_ * S_ * S_ + j * S_ + i);
    return shared::pathKey(s_.settings.seed, slotKey(rdm_.id.slot), uint32_t(rdm_.id.level), texel,
                           sample);
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
      if (sets_.full.size() > 4096) sortUnique(sets_.full), sortUnique(sets_.first);
      return l;
    } else {
      return tracePath<kSun, kEmitters>(s_.world, s_.settings.max_bounces, origin_, dir, path_key,
                                        PathOrigin::kRdmFace, stats_);
    }
  }
  vec3 diffuseSample(int i, int j, uint32_t sample) {
    uint32_t k = key(i, j, sample);
    vec3 local = sampleCosineHemisphere(shared::randomUniform(k, 0, shared::kDimOrigin0),
                                        shared::randomUniform(k, 0, shared::kDimOrigin1));
    if (local.z <= 0.0f) return vec3(0.0f);
    return trace(frame_.toWorld(local), k);
  }
  // Doubles the sample count while the target error is not met (target-error mode).
  bool refine(const SampleEstimator& e, uint32_t n, uint32_t& target) const {
    if (s_.options.target_error <= 0.0) return false;
    uint32_t cap = uint32_t(s_.settings.spp) * uint32_t(std::max(1, s_.options.max_spp_factor));
    if (n >= cap || e.relativeError() < s_.options.target_error) return false;
    target = std::min(cap, n * 2);
    return true;
  }
  void bakeTexel(int i, int j) {
    const int level = rdm_.id.level;
    const float alpha = shared::roughnessAlpha(level);
    const ivec3 d = shared::texelCentralDirection(i, j, S_);
    const vec3 w = glm::normalize(frame_.toWorld(vec3(d)));
    SampleEstimator e;
    uint32_t n = 0, target = uint32_t(s_.settings.spp);
    while (true) {
      for (uint32_t sample = n; sample < target; ++sample) {
        uint32_t k = key(i, j, sample);
        float u0 = shared::randomUniform(k, 0, shared::kDimOrigin0);
        float u1 = shared::randomUniform(k, 0, shared::kDimOrigin1);
        if (level == 0) {
          vec2 uv(2.0f * (float(i) + u0) / float(S_) - 1.0f,
                  2.0f * (float(j) + u1) / float(S_) - 1.0f);
          vec3 l = frame_.toWorld(shared::hemiOctDecode(uv));
          e.add(glm::dot(l, frame_.n) > 0.0f ? trace(l, k) : vec3(0.0f), 1.0f);
          continue;
        }
        vec3 h = frameAround(w).toWorld(sampleGgxNdf(alpha, u0, u1));
        vec3 l = 2.0f * glm::dot(w, h) * h - w;
        float wl = glm::dot(w, l);
        if (glm::dot(frame_.n, l) <= 0.0f || wl <= 0.0f) continue;
        e.add(trace(glm::normalize(l), k), wl);
      }
      n = target;
      if (!refine(e, n, target)) break;
    }
    store(i, j, e, n);
  }
  void store(int i, int j, const SampleEstimator& e, uint32_t samples) {
    const ivec2 px = shared::rdmTexelPixel(0, 0, S_, face_, i, j);
    const ivec3 d = shared::texelCentralDirection(i, j, S_);
    const ivec3 dir = d.x * shared::faceTangent(face_) + d.y * shared::faceBitangent(face_) +
                      d.z * shared::faceNormal(face_);
    glm::dvec3 mean = e.mean(), err = e.stderror();
    for (int c = 0; c < 3; ++c) {
      rdm_.image.at(px.x, px.y, c) = float(mean[c]);
      rdm_.stderr_rgb[(size_t(px.y) * rdm_.image.width + px.x) * 3 + c] = float(err[c]);
    }
    if constexpr (kRecord) {
      std::vector<uint32_t> central;  // central rays belong to both sets (docs/spec.md section 8)
      rdm_.image.at(px.x, px.y, 3) = exactCentralDepth(s_.world, ivec3(origin_), dir, &central);
      sets_.first.insert(sets_.first.end(), central.begin(), central.end());
      sets_.full.insert(sets_.full.end(), central.begin(), central.end());
    } else {
      rdm_.image.at(px.x, px.y, 3) = exactCentralDepth(s_.world, ivec3(origin_), dir);
    }
    sets_.max_samples = std::max(sets_.max_samples, samples);
  }

  const Shared& s_;
  RdmData& rdm_;
  const int face_;
  PathStats& stats_;
  UnitSets& sets_;
  const int S_;
  const Frame frame_;
  const vec3 origin_;
};

void appendBits(const std::vector<uint64_t>& bits, std::vector<uint32_t>& out) {
  for (size_t w = 0; w < bits.size(); ++w) {
    for (uint64_t b = bits[w]; b != 0; b &= b - 1)
      out.push_back(uint32_t(w * 64 + size_t(__builtin_ctzll(b))));
  }
}

template <bool kSun, bool kEmitters, bool kRecord>
void runUnit(const Shared& s, const Unit& u, PathStats& stats, UnitSets& sets) {
  RdmData& rdm = s.out[u.rdm];
  if (kRecord && s.world.slots.size() <= kMaxBitsetSlots) {
    sets.full_bits.assign((s.world.slots.size() + 63) / 64, 0);
    sets.first_bits.assign(sets.full_bits.size(), 0);
  }
  FaceBaker<kSun, kEmitters, kRecord> baker(s, rdm, u.face, stats, sets);
  if (rdm.id.level == shared::kDiffuseLevel) {
    baker.bakeDiffuseFace();
  } else {
    baker.bakeTile(u);
  }
  if (kRecord && !sets.full_bits.empty()) {
    appendBits(sets.full_bits, sets.full), appendBits(sets.first_bits, sets.first);
    sets.full_bits = {}, sets.first_bits = {};
  }
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

void mergeSets(const std::vector<Unit>& units, std::vector<UnitSets>& sets,
               std::vector<RdmData>& out) {
  for (size_t i = 0; i < units.size(); ++i) {
    RdmData& rdm = out[units[i].rdm];
    rdm.full_set.insert(rdm.full_set.end(), sets[i].full.begin(), sets[i].full.end());
    rdm.first_set.insert(rdm.first_set.end(), sets[i].first.begin(), sets[i].first.end());
    rdm.smooth_vertex = rdm.smooth_vertex || sets[i].smooth;
    sets[i] = UnitSets();
  }
  for (RdmData& rdm : out) sortUnique(rdm.full_set), sortUnique(rdm.first_set);
}

std::vector<Unit> planUnits(const VoxelWorld& world, std::vector<RdmData>& out,
                            BakeReport& report) {
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
      if (rdm.id.level == shared::kDiffuseLevel) {
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

}  // namespace

struct BakeSession::Impl {
  const VoxelWorld& world;
  const BakeSettings settings;
  const BakeOptions options;
  BakeResult result;
  std::vector<BakeUnit> units;
  std::vector<UnitSets> unit_sets;
  UnitFn kernel;
  Shared shared;
  Impl(const VoxelWorld& w, const BakeSettings& s, const BakeOptions& o)
      : world(w),
        settings(s),
        options(o),
        kernel(nullptr),
        shared{world, settings, options, result.rdms} {}
};

BakeSession::BakeSession(const VoxelWorld& world, const BakeSettings& settings,
                         const std::vector<RdmId>& rdms, const BakeOptions& options)
    : impl_(new Impl(world, settings, options)) {
  BakeResult& result = impl_->result;
  result.report.effects = sceneEffects(world);
  for (const RdmId& id : rdms) {
    RdmData data;
    data.id = id;
    data.image = Image(2 * id.size, 3 * id.size, 4);
    data.stderr_rgb.assign(size_t(data.image.width) * data.image.height * 3, 0.0f);
    result.rdms.push_back(std::move(data));
  }
  impl_->units = planUnits(world, result.rdms, result.report);
  impl_->kernel = selectKernel(result.report.effects, impl_->options);
  impl_->unit_sets.resize(impl_->units.size());
}

BakeSession::~BakeSession() {
  delete impl_;
}

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
  impl_->kernel(impl_->shared, impl_->units[i], stats, u);
  if (!impl_->options.record_slot_sets) return stats.rays;
  sortUnique(u.full), sortUnique(u.first);
  if (sets) {
    sets->full = std::move(u.full), sets->first = std::move(u.first);
    sets->smooth_vertex = u.smooth;
    u.full.clear(), u.first.clear(), u.smooth = false;
  }
  return stats.rays;
}

BakeResult BakeSession::finish(double seconds, uint64_t rays, bool cancelled) {
  BakeResult& result = impl_->result;
  for (size_t i = 0; i < impl_->units.size(); ++i) {
    uint32_t& m = result.rdms[size_t(impl_->units[i].rdm)].max_samples;
    m = std::max(m, impl_->unit_sets[i].max_samples);
  }
  if (impl_->options.record_slot_sets) mergeSets(impl_->units, impl_->unit_sets, result.rdms);
  result.report.rdms = int(result.rdms.size());
  result.report.rays = rays;
  result.report.cancelled = cancelled;
  result.report.seconds = seconds;
  summariseBake(result.rdms, result.report);
  return std::move(result);
}

BakeResult bakeRdms(const VoxelWorld& world, const BakeSettings& settings,
                    const std::vector<RdmId>& rdms, const BakeOptions& options) {
  auto start = std::chrono::steady_clock::now();
  BakeSession session(world, settings, rdms, options);
  const std::vector<BakeUnit>& units = session.units();
  const size_t rdm_count = session.rdms().size();
  std::vector<std::atomic<int>> remaining(rdm_count);
  uint64_t texels_total = 0;
  for (const BakeUnit& u : units) {
    remaining[u.rdm].fetch_add(1);
    texels_total += uint64_t(u.x1 - u.x0) * uint64_t(u.y1 - u.y0);
  }
  std::atomic<int> rdms_done{0};
  for (auto& r : remaining) rdms_done += r.load() == 0 ? 1 : 0;
  std::atomic<size_t> next{0};
  std::atomic<uint64_t> rays{0}, texels_done{0};
  std::atomic<int> workers_left{0};
  std::atomic<bool> cancelled{false};
  int thread_count = options.threads > 0 ? options.threads
                                         : int(std::max(1u, std::thread::hardware_concurrency()));
  auto work = [&] {
    for (size_t i; (i = next.fetch_add(1)) < units.size();) {
      if (options.cancel && options.cancel->load()) {
        cancelled = true;
        break;
      }
      rays += session.runUnit(i);
      const BakeUnit& u = units[i];
      texels_done += uint64_t(u.x1 - u.x0) * uint64_t(u.y1 - u.y0);
      if (remaining[u.rdm].fetch_sub(1) == 1) ++rdms_done;
    }
    --workers_left;
  };
  auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  auto progress = [&] {
    if (options.on_progress)
      options.on_progress({rdms_done.load(), int(rdm_count), rays.load(), elapsed(),
                           texels_done.load(), texels_total});
  };
  progress();  // the 0 % report, before any work
  std::vector<std::thread> threads;
  workers_left = thread_count;
  for (int t = 0; t < thread_count; ++t) threads.emplace_back(work);
  while (workers_left.load() > 0) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    progress();
  }
  for (std::thread& t : threads) t.join();
  if (!cancelled) progress();
  return session.finish(elapsed(), rays.load(), cancelled.load());
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
