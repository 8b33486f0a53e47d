// One bake on a Vulkan device that already has its pipelines (vulkan_context.h): scene
// upload, the plan (vulkan_bake_plan.h), batches of paths dispatched until none is active, and
// the per-texel estimators (double, in texel then sample order, as the CPU accumulates); a
// radiance map's texels go to its FaceMapBuilder, and a finished map is derived into its
// consumers' faces. With slot-set recording the kernel ORs the slots its walks enter into one
// full and one first-segment bitset per slot-set owner of the batch (rdm_gpu_layout.h), which
// the host reads back after each batch; central rays are recorded in the plan, on the host.
#if RDM_HAVE_VULKAN

#include <algorithm>
#include <chrono>
#include <cstring>
#include <functional>

#include "rdm/bake/bake_stats.h"
#include "rdm/bake/slot_set.h"
#include "rdm/base/check.h"
#include "rdm/trace/traversal.h"
#include "rdm/transport/rdm_shared_cpp.h"
#include "rdm/transport/sobol.h"
#include "rdm/vulkan/dispatch_budget.h"
#include "vulkan_bake_plan.h"
#include "vulkan_context.h"
#include "vulkan_prefilter.h"

namespace rdm::vkbake {
namespace {

using glm::ivec3;
using glm::vec3;

// The slot-set buffer's size cap: a batch holds at most this many bytes of bitsets, so a
// large grid bakes fewer RDMs per batch (cut at an RDM boundary) rather than fail.
constexpr uint64_t kSlotSetBudgetBytes = uint64_t(64) << 20;

template <class T>
void upload(Buffer* b, const std::vector<T>& data) {
  if (!data.empty()) std::memcpy(b->mapped, data.data(), data.size() * sizeof(T));
}

// Appends the linear slot index of every set bit of `bits` (`count` words) to `out`.
void appendBits(const uint32_t* bits, uint32_t count, std::vector<uint32_t>& out) {
  for (uint32_t w = 0; w < count; ++w) {
    for (uint32_t b = bits[w]; b != 0; b &= b - 1)
      out.push_back(w * 32 + uint32_t(__builtin_ctz(b)));
  }
}

gpu::GpuParams sceneParams(const VoxelWorld& world, const BakeSettings& settings) {
  gpu::GpuParams params{};
  const ivec3 extent = world.voxelExtent();
  params.world = glm::ivec4(world.size, extent.x + extent.y + extent.z + 8);
  params.config = glm::uvec4(settings.seed, uint32_t(std::max(0, settings.max_bounces)),
                             uint32_t(world.emitters.emitters.size()), world.sun.present ? 1u : 0u);
  params.sun_direction = glm::vec4(world.sun.direction, world.sun.pdf);
  params.sun_radiance = glm::vec4(world.sun.radiance, world.sun.one_minus_cos_max);
  params.sun_irradiance = glm::vec4(world.sun.irradiance, world.sun.disc_c2);
  params.sky_zenith = glm::vec4(world.sky.zenith, world.emitters.total_luminance);
  params.sky_horizon = glm::vec4(world.sky.horizon, 0.0f);
  params.sky_ground = glm::vec4(world.sky.ground, 0.0f);
  return params;
}

std::vector<gpu::GpuMaterial> sceneMaterials(const VoxelWorld& world) {
  std::vector<gpu::GpuMaterial> materials(256);
  for (size_t p = 0; p < 256; ++p) {
    const Material& m = world.materials[p];
    materials[p].base_metallic = glm::vec4(m.base_color, m.metallic);
    materials[p].f0_alpha = glm::vec4(m.f0, m.alpha);
    materials[p].emission = glm::vec4(m.emission, 0.0f);
    materials[p].flags = glm::uvec4(m.emissive ? 1u : 0u, uint32_t(m.roughness), 0u, 0u);
  }
  return materials;
}

// Palette bytes, four per word, then each block's 4^3 brick mask (brickEmpty in bake.comp).
std::vector<uint32_t> sceneVoxels(const VoxelWorld& world) {
  const size_t blocks = world.blocks.size();
  RDM_CHECK(world.occupancy.size() == blocks);
  std::vector<uint32_t> voxels(blocks * (1024 + 2), 0u);
  for (size_t b = 0; b < blocks; ++b) {
    for (size_t v = 0; v < 4096; ++v)
      voxels[b * 1024 + v / 4] |= uint32_t(world.blocks[b].voxels[v]) << (8 * (v % 4));
    voxels[blocks * 1024 + 2 * b] = uint32_t(world.occupancy[b].bricks);
    voxels[blocks * 1024 + 2 * b + 1] = uint32_t(world.occupancy[b].bricks >> 32);
  }
  return voxels;
}

// Takes each batch's results in job, then sample order (the CPU's order): an RDM texel
// group's estimate into its RDM, a map texel's into its map's builder; a finished map goes to
// the prefilter pass, which derives its consumers' faces.
class ResultSink {
 public:
  // `work_done(r, n)`: n of RDM r's pending texel jobs or map faces are finished.
  ResultSink(const BakeSettings& settings, BakePlan& plan, BakeResult& result,
             DevicePrefilter& prefilter, std::function<void(int, int)> work_done)
      : seed_(settings.seed),
        plan_(plan),
        result_(result),
        prefilter_(prefilter),
        work_done_(std::move(work_done)) {}
  // The first device error of the prefilter pass, if any.
  const Status& status() const { return status_; }

  // Samples [first_sample, first_sample + count) of job `index`.
  void add(size_t index, uint32_t first_sample, const glm::vec4* values, uint32_t count) {
    const Job& job = plan_.jobs[index];
    if (job.group != group_) {
      finishGroup();
      group_ = job.group;
      if (job.map >= 0) {
        const int S = plan_.maps[size_t(job.map)].size;
        const uint32_t texel = uint32_t(job.face * S * S + job.j * S + job.i);
        sobol_key_ = shared::pathKey(seed_, job.gpu.data.x, 0u, texel, 0u);
      }
    }
    for (uint32_t s = 0; s < count; ++s) {
      const glm::vec4 v = values[s];
      RDM_CHECK(v.w != gpu::kWeightWalkBoundExceeded && "the kernel's walk ran past its bound");
      estimator_.add(vec3(v), v.w);
      if (job.map >= 0) {
        const glm::vec2 p = shared::owenSobolPoint(first_sample + s, sobol_key_);
        const int S = plan_.maps[size_t(job.map)].size;
        cosine_.add(shared::texelFootprintPoint(job.i, job.j, S, p.x, p.y), vec3(v));
      }
    }
    samples_ = first_sample + count;
  }

  void finishGroup() {
    if (group_ < 0) return;
    const Job& first = plan_.jobs[size_t(group_)];
    if (first.map >= 0) {
      finishMapTexel(first);
    } else {
      finishRdmGroup(first);
    }
    estimator_ = SampleEstimator(), cosine_ = CosineSums();
    group_ = -1;
  }

 private:
  void finishRdmGroup(const Job& first) {
    RdmData& rdm = result_.rdms[size_t(first.rdm)];
    const int S = rdm.id.size;
    const size_t count = rdm.id.level == shared::kDiffuseLevel ? size_t(S) * S : 1;
    const glm::dvec3 mean = estimator_.mean(), err = estimator_.stderror();
    for (size_t n = 0; n < count; ++n) {
      const Job& job = plan_.jobs[size_t(group_) + n];
      storeRadiance(rdm, job.face, job.i, job.j, mean, err);
    }
    work_done_(first.rdm, int(count));
  }

  void finishMapTexel(const Job& job) {
    PlannedMap& map = plan_.maps[size_t(job.map)];
    map.builder->setTexel(job.i, job.j, estimator_, samples_, cosine_);
    if (--map.jobs_left > 0) return;
    FaceMap finished;
    map.builder->finish(finished);
    map.builder.reset();
    Status s = prefilter_.derive(std::move(finished), map.face, map.consumers, result_.rdms);
    if (!s && status_.ok()) status_ = s;
  }

  const uint32_t seed_;
  BakePlan& plan_;
  BakeResult& result_;
  DevicePrefilter& prefilter_;
  const std::function<void(int, int)> work_done_;
  Status status_;
  int group_ = -1;
  uint32_t samples_ = 0, sobol_key_ = 0;
  SampleEstimator estimator_;
  CosineSums cosine_;
};

}  // namespace

Expected<BakeResult> bakeOnContext(Context& ctx, const VulkanDeviceInfo& device,
                                   const VoxelWorld& world, const BakeSettings& settings,
                                   const std::vector<RdmId>& rdms,
                                   const VulkanBakeOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  BakeResult result;
  BakeReport& report = result.report;
  report.effects = sceneEffects(world);
  const bool sun = report.effects.sun || options.all_effects;
  const bool emit = report.effects.emitters || options.all_effects;
  const bool record = options.record_slot_sets;
  auto pipeline = ctx.pipeline(sun, emit, record);
  if (!pipeline) return pipeline.status();

  // --- Scene buffers ------------------------------------------------------------------
  const gpu::GpuParams params = sceneParams(world, settings);
  const std::vector<gpu::GpuMaterial> materials = sceneMaterials(world);
  const std::vector<uint32_t> voxels = sceneVoxels(world);
  std::vector<gpu::GpuEmitter> emitters;
  for (const Emitter& e : world.emitters.emitters)
    emitters.push_back({glm::ivec4(e.voxel, e.face), glm::vec4(e.radiance, 0.0f)});

  const uint32_t spp = uint32_t(settings.spp);
  const uint64_t budget_paths = std::max<uint64_t>(gpu::kWorkgroupSize, options.max_batch_paths);
  const uint64_t storage_range = ctx.props.limits.maxStorageBufferRange;
  const uint64_t batch_paths =
      std::min<uint64_t>(budget_paths, storage_range / sizeof(gpu::GpuPathState));
  const uint32_t max_jobs = uint32_t(std::max<uint64_t>(1, batch_paths / spp));
  const uint32_t loop_budget = std::clamp<uint32_t>(options.loop_budget, 256u, gpu::kMaxLoopBudget);
  BakePlan plan = planBake(world, settings, rdms, result);
  // Slot sets: 2W + 1 words per owner of a batch; a batch holds at most set_owners owners.
  const uint32_t set_words = uint32_t((world.slots.size() + 31) / 32);
  const uint64_t owner_set_bytes = (2 * uint64_t(set_words) + 1) * sizeof(uint32_t);
  const uint64_t set_owners = std::min<uint64_t>(
      {std::max<uint64_t>(1, std::min(kSlotSetBudgetBytes, storage_range) / owner_set_bytes),
       std::max<size_t>(1, plan.owners.size()), max_jobs});

  Buffers buffers(ctx);
  std::vector<Buffer*> bound;
  auto make = [&](uint64_t bytes, const char* what) -> Status {
    auto b = buffers.create(bytes, what);
    if (!b) return b.status();
    bound.push_back(*b);
    return {};
  };
  // In binding order (rdm_gpu_layout.h).
  const std::pair<uint64_t, const char*> sizes[gpu::kBindingCount] = {
      {sizeof(params), "parameter"},
      {world.slots.size() * sizeof(int32_t), "slot grid"},
      {voxels.size() * sizeof(uint32_t), "voxel"},
      {materials.size() * sizeof(gpu::GpuMaterial), "material"},
      {emitters.size() * sizeof(gpu::GpuEmitter), "emitter"},
      {world.emitters.cdf.size() * sizeof(float), "emitter CDF"},
      {uint64_t(std::min<uint64_t>(max_jobs, batch_paths)) * sizeof(gpu::GpuJob), "job"},
      {batch_paths * sizeof(gpu::GpuPathState), "path state"},
      {batch_paths * sizeof(glm::vec4), "result"},
      {sizeof(gpu::GpuCounters), "counter"},
      {record ? set_owners * owner_set_bytes : 16, "slot-set"}};
  for (const auto& [bytes, what] : sizes) {
    if (Status s = make(bytes, what); !s) return s;
  }
  Buffer* b_jobs = bound[gpu::kBindingJobs];
  Buffer* b_paths = bound[gpu::kBindingPaths];
  Buffer* b_results = bound[gpu::kBindingResults];
  Buffer* b_counters = bound[gpu::kBindingCounters];
  Buffer* b_sets = bound[gpu::kBindingSlotSets];
  std::memcpy(bound[gpu::kBindingParams]->mapped, &params, sizeof(params));
  upload(bound[gpu::kBindingSlots], world.slots);
  upload(bound[gpu::kBindingVoxels], voxels);
  upload(bound[gpu::kBindingMaterials], materials);
  upload(bound[gpu::kBindingEmitters], emitters);
  upload(bound[gpu::kBindingEmitterCdf], world.emitters.cdf);
  std::memset(b_sets->mapped, 0, b_sets->size);
  ctx.bind(bound, ctx.descriptor_set);

  VulkanBakeInfo info;
  info.device = device;
  info.setup_seconds = elapsed();

  // An RDM is complete once its texel jobs or map faces are: its sets are merged and sorted,
  // and a streaming bake hands it out and frees it.
  RdmTexels texels(world, record, result.rdms.size());
  std::vector<RdmErrorStats> errors(result.rdms.size());
  int rdms_done = 0;
  auto complete = [&](size_t r) {
    RdmData& rdm = result.rdms[r];
    texels.ensure(rdm, r);  // every face skipped: no job allocated it
    if (record && plan.maps_owner[r] >= 0) {
      const OwnerSets& maps = plan.owners[size_t(plan.maps_owner[r])];
      rdm.full_set.insert(rdm.full_set.end(), maps.full.begin(), maps.full.end());
      rdm.first_set.insert(rdm.first_set.end(), maps.first.begin(), maps.first.end());
      rdm.smooth_vertex = rdm.smooth_vertex || maps.smooth;
    }
    sortUniqueSlots(rdm.full_set), sortUniqueSlots(rdm.first_set);
    errors[r] = rdmErrorStats(rdm);
    ++rdms_done;
    if (options.on_rdm_done) options.on_rdm_done(rdm), texels.release(rdm);
  };
  auto work_done = [&](int r, int count) {
    if ((plan.pending[size_t(r)] -= count) == 0) complete(size_t(r));
  };
  DevicePrefilter prefilter(ctx, buffers, options.max_prefilter_texels,
                            [&](int r) { work_done(r, 1); });
  if (Status s = prefilter.prepare(plan, result.rdms); !s) return s;
  ResultSink sink(settings, plan, result, prefilter, work_done);
  for (size_t r = 0; r < result.rdms.size(); ++r)
    if (plan.pending[r] == 0) complete(r);
  // The batch's sets into its owners o0..o1 (batch-local 0..o1 - o0); the words are cleared.
  auto collectSets = [&](int o0, int o1) {
    uint32_t* words = static_cast<uint32_t*>(b_sets->mapped);
    for (int o = o0; o <= o1; ++o) {
      const uint32_t* w = words + size_t(o - o0) * (2 * size_t(set_words) + 1);
      OwnerSets& owner = plan.owners[size_t(o)];
      RdmData* rdm = owner.rdm >= 0 ? &result.rdms[size_t(owner.rdm)] : nullptr;
      appendBits(w, set_words, rdm ? rdm->full_set : owner.full);
      appendBits(w + set_words, set_words, rdm ? rdm->first_set : owner.first);
      bool& smooth = rdm ? rdm->smooth_vertex : owner.smooth;
      smooth = smooth || w[2 * size_t(set_words)] != 0;
    }
    std::memset(words, 0, size_t(o1 - o0 + 1) * owner_set_bytes);
  };

  const std::vector<Job>& jobs = plan.jobs;
  uint64_t rays = 0;
  bool cancelled = false;
  auto progress = [&] {
    if (options.on_progress)
      options.on_progress({rdms_done, int(result.rdms.size()), rays, elapsed()});
  };
  size_t j0 = 0;
  uint32_t s0 = 0;
  DispatchBudget budget(options.max_dispatch_seconds, loop_budget, max_jobs);
  info.min_loop_budget = loop_budget;
  while (j0 < jobs.size() && !cancelled) {
    uint32_t nj = uint32_t(std::min<size_t>(budget.maxJobs(), jobs.size() - j0));
    const int o0 = jobs[j0].owner;
    if (record) {  // at most set_owners owners: jobs are in owner order
      const auto first = jobs.begin() + std::ptrdiff_t(j0);
      nj = uint32_t(
          std::partition_point(first, first + nj,
                               [&](const Job& j) { return uint64_t(j.owner - o0) < set_owners; }) -
          first);
    }
    const uint32_t ns =
        spp <= batch_paths ? spp : uint32_t(std::min<uint64_t>(batch_paths, spp - s0));
    const uint32_t paths = nj * ns;
    for (uint32_t n = 0; n < nj; ++n) {
      const Job& job = jobs[j0 + n];
      if (job.rdm >= 0) texels.ensure(result.rdms[size_t(job.rdm)], size_t(job.rdm));
      if (job.map >= 0 && !plan.maps[size_t(job.map)].started) {
        plan.maps[size_t(job.map)].started = true;
        for (int c : plan.maps[size_t(job.map)].consumers)
          texels.ensure(result.rdms[size_t(c)], size_t(c));
      }
      gpu::GpuJob g = jobs[j0 + n].gpu;
      g.data.w = uint32_t(jobs[j0 + n].owner - o0);
      static_cast<gpu::GpuJob*>(b_jobs->mapped)[n] = g;
    }
    ++info.batches;
    uint64_t dispatches = 0;
    for (bool first = true;; first = false) {
      if (options.cancel && options.cancel->load()) {
        cancelled = true;
        break;
      }
      std::memset(b_counters->mapped, 0, sizeof(gpu::GpuCounters));
      const gpu::GpuPush push{glm::uvec4(nj, ns, s0, budget.loopBudget())};
      info.min_loop_budget = std::min<uint64_t>(info.min_loop_budget, budget.loopBudget());
      const auto dispatched = std::chrono::steady_clock::now();
      if (Status s =
              ctx.dispatch(*pipeline, push, paths, first ? b_paths : nullptr, ctx.descriptor_set);
          !s)
        return s;
      const double took =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - dispatched).count();
      budget.observe(took);
      info.max_dispatch_seconds = std::max(info.max_dispatch_seconds, took);
      ++dispatches;
      const gpu::GpuCounters counters = *static_cast<const gpu::GpuCounters*>(b_counters->mapped);
      rays += uint64_t(counters.values.y) + (uint64_t(counters.values.z) << 32);
      progress();
      if (counters.values.x == 0) break;
    }
    info.dispatches += dispatches;
    info.max_dispatches_per_batch = std::max(info.max_dispatches_per_batch, dispatches);
    if (cancelled) break;
    if (record) collectSets(o0, jobs[j0 + nj - 1].owner);
    const glm::vec4* out = static_cast<const glm::vec4*>(b_results->mapped);
    for (uint32_t n = 0; n < nj; ++n) sink.add(j0 + n, s0, out + size_t(n) * ns, ns);
    if (!sink.status()) return sink.status();
    // The maps this batch finished, derived now, so their RDMs leave with this batch.
    if (Status s = prefilter.flush(result.rdms); !s) return s;
    s0 += ns;
    if (s0 >= spp) s0 = 0, j0 += nj;
    progress();
  }
  if (!cancelled) {
    sink.finishGroup();
    if (!sink.status()) return sink.status();
    if (Status s = prefilter.flush(result.rdms); !s) return s;
  }

  info.prefilter_dispatches = prefilter.dispatches();
  info.texels_prefiltered = prefilter.texelsDerived();
  info.prefilter_seconds = prefilter.seconds();
  report.rdms = int(result.rdms.size());
  report.rays = rays;
  report.cancelled = cancelled;
  report.seconds = elapsed();
  for (size_t r = 0; r < result.rdms.size(); ++r) {  // a cancelled bake's unfinished RDMs
    if (plan.pending[r] != 0 && !result.rdms[r].image.pixels.empty())
      errors[r] = rdmErrorStats(result.rdms[r]);
  }
  summariseBake(errors, report);
  report.peak_rdms_held = texels.peakHeld();
  if (options.info) *options.info = info;
  return result;
}

}  // namespace rdm::vkbake

#endif  // RDM_HAVE_VULKAN
