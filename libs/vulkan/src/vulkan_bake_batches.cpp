// One bake on a Vulkan device that already has its pipelines (vulkan_context.h): scene
// upload, the plan (RDMs, skipped faces, texel jobs, the exact central depths on the CPU with
// exactCentralDepth, identical to the CPU backend), batches of paths dispatched until none
// is active, and the per-texel estimators (double, in texel then sample order, as the CPU
// accumulates). With slot-set recording the kernel ORs the slots its walks enter into one
// full and one first-segment bitset per RDM of the batch (rdm_gpu_layout.h), which the host
// reads back after each batch; central rays are recorded here, on the host.
#if RDM_HAVE_VULKAN

#include <algorithm>
#include <chrono>
#include <cstring>

#include "rdm/bake/bake_stats.h"
#include "rdm/bake/slot_set.h"
#include "rdm/base/check.h"
#include "rdm/trace/traversal.h"
#include "rdm/transport/rdm_shared_cpp.h"
#include "vulkan_context.h"

namespace rdm::vkbake {
namespace {

using glm::ivec3;
using glm::vec3;

// The slot-set buffer's size cap: a batch holds at most this many bytes of bitsets, so a
// large grid bakes fewer RDMs per batch (cut at an RDM boundary) rather than fail.
constexpr uint64_t kSlotSetBudgetBytes = uint64_t(64) << 20;

// A texel job and the group its samples accumulate into: the texel itself, or at level 7
// every texel of the face (the face mean).
struct Job {
  int rdm, face, i, j;
  int group;  // index of the group's first job
  gpu::GpuJob gpu;
};

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

// The slots an RDM's central rays enter, gathered ray by ray: a bitset over the grid answers
// membership, the member list gives the sorted set and clears the bitset for the next RDM.
class SlotGather {
 public:
  explicit SlotGather(size_t slots) : bits_((slots + 63) / 64, 0) {}
  std::vector<uint32_t> ray;  // exactCentralDepth appends one ray's slots here
  void addRay() {
    for (uint32_t s : ray) {
      uint64_t& word = bits_[s >> 6];
      const uint64_t bit = uint64_t(1) << (s & 63);
      if (!(word & bit)) word |= bit, members_.push_back(s);
    }
    ray.clear();
  }
  std::vector<uint32_t> take() {
    for (uint32_t s : members_) bits_[s >> 6] = 0;
    std::sort(members_.begin(), members_.end());
    std::vector<uint32_t> out;
    out.swap(members_);
    return out;
  }

 private:
  std::vector<uint64_t> bits_;
  std::vector<uint32_t> members_;
};

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

// RDM images, skipped faces and texel jobs in (rdm, face, j, i) order, with every texel's
// depth from the CPU's exact central ray; `record`: the central rays' slots start both sets.
std::vector<Job> planJobs(const VoxelWorld& world, const std::vector<RdmId>& rdms, uint32_t spp,
                          bool record, BakeResult& result) {
  BakeReport& report = result.report;
  std::vector<Job> jobs;
  SlotGather central(record ? world.slots.size() : 0);
  for (const RdmId& id : rdms) {
    RdmData data;
    data.id = id;
    data.image = Image(2 * id.size, 3 * id.size, 4);
    data.stderr_rgb.assign(size_t(data.image.width) * data.image.height * 3, 0.0f);
    data.max_samples = spp;
    const int r = int(result.rdms.size());
    const int S = id.size;
    const ivec3 origin_base = id.slot * 16 + ivec3(8);
    for (int f = 0; f < 6; ++f) {
      data.skipped[size_t(f)] = faceSkipped(world, id.slot, f);
      if (data.skipped[size_t(f)]) {
        ++report.faces_skipped;
        continue;
      }
      ++report.faces_baked;
      const ivec3 origin = origin_base + 8 * shared::faceNormal(f);
      const int group_start = int(jobs.size());
      for (int j = 0; j < S; ++j)
        for (int i = 0; i < S; ++i) {
          Job job{r, f, i, j, id.level == shared::kDiffuseLevel ? group_start : int(jobs.size()),
                  {}};
          job.gpu.data =
              glm::uvec4(slotKey(id.slot), uint32_t(id.level) | uint32_t(f) << 4 | uint32_t(S) << 8,
                         uint32_t(i) | uint32_t(j) << 16, 0u);
          jobs.push_back(job);
          const ivec3 d = shared::texelCentralDirection(i, j, S);
          const ivec3 dir = d.x * shared::faceTangent(f) + d.y * shared::faceBitangent(f) +
                            d.z * shared::faceNormal(f);
          const glm::ivec2 px = shared::rdmTexelPixel(0, 0, S, f, i, j);
          data.image.at(px.x, px.y, 3) =
              exactCentralDepth(world, origin, dir, record ? &central.ray : nullptr);
          if (record) central.addRay();
        }
    }
    if (record) {
      data.first_set = central.take();
      data.full_set = data.first_set;
    }
    result.rdms.push_back(std::move(data));
  }
  return jobs;
}

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
  // Slot sets: 2W + 1 words per RDM of a batch; a batch holds at most set_rdms RDMs.
  const uint32_t set_words = uint32_t((world.slots.size() + 31) / 32);
  const uint64_t rdm_set_bytes = (2 * uint64_t(set_words) + 1) * sizeof(uint32_t);
  const uint64_t set_rdms = std::min<uint64_t>(
      {std::max<uint64_t>(1, std::min(kSlotSetBudgetBytes, storage_range) / rdm_set_bytes),
       std::max<size_t>(1, rdms.size()), max_jobs});

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
      {record ? set_rdms * rdm_set_bytes : 16, "slot-set"}};
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
  ctx.bind(bound);

  VulkanBakeInfo info;
  info.device = device;
  info.setup_seconds = elapsed();

  std::vector<Job> jobs = planJobs(world, rdms, spp, record, result);
  std::vector<int> jobs_left(result.rdms.size(), 0);
  for (const Job& j : jobs) ++jobs_left[size_t(j.rdm)];
  int rdms_done = 0;
  for (int left : jobs_left) rdms_done += left == 0 ? 1 : 0;

  // --- Batches: jobs [j0, j0 + nj) x samples [s0, s0 + ns) --------------------------------
  SampleEstimator estimator;
  int current_group = -1;
  auto finishGroup = [&](int group) {
    if (group < 0) return;
    const Job& first = jobs[size_t(group)];
    RdmData& rdm = result.rdms[size_t(first.rdm)];
    const int S = rdm.id.size;
    const size_t count = rdm.id.level == shared::kDiffuseLevel ? size_t(S) * S : 1;
    const glm::dvec3 mean = estimator.mean(), err = estimator.stderror();
    for (size_t n = 0; n < count; ++n) {
      const Job& job = jobs[size_t(group) + n];
      const glm::ivec2 px = shared::rdmTexelPixel(0, 0, S, job.face, job.i, job.j);
      for (int c = 0; c < 3; ++c) {
        rdm.image.at(px.x, px.y, c) = float(mean[c]);
        rdm.stderr_rgb[(size_t(px.y) * rdm.image.width + px.x) * 3 + c] = float(err[c]);
      }
    }
    estimator = SampleEstimator();
  };
  // The batch's sets into its RDMs r0..r1 (batch-local 0..r1 - r0); the words are cleared.
  auto collectSets = [&](int r0, int r1) {
    uint32_t* words = static_cast<uint32_t*>(b_sets->mapped);
    for (int r = r0; r <= r1; ++r) {
      uint32_t* w = words + size_t(r - r0) * (2 * size_t(set_words) + 1);
      RdmData& rdm = result.rdms[size_t(r)];
      appendBits(w, set_words, rdm.full_set);
      appendBits(w + set_words, set_words, rdm.first_set);
      rdm.smooth_vertex = rdm.smooth_vertex || w[2 * size_t(set_words)] != 0;
    }
    std::memset(words, 0, size_t(r1 - r0 + 1) * rdm_set_bytes);
  };

  uint64_t rays = 0;
  bool cancelled = false;
  auto progress = [&] {
    if (options.on_progress)
      options.on_progress({rdms_done, int(result.rdms.size()), rays, elapsed()});
  };
  size_t j0 = 0;
  uint32_t s0 = 0;
  while (j0 < jobs.size() && !cancelled) {
    uint32_t nj = uint32_t(std::min<size_t>(max_jobs, jobs.size() - j0));
    const int r0 = jobs[j0].rdm;
    if (record) {  // at most set_rdms RDMs: jobs are in RDM order
      const auto first = jobs.begin() + std::ptrdiff_t(j0);
      nj = uint32_t(
          std::partition_point(first, first + nj,
                               [&](const Job& j) { return uint64_t(j.rdm - r0) < set_rdms; }) -
          first);
    }
    const uint32_t ns =
        spp <= batch_paths ? spp : uint32_t(std::min<uint64_t>(batch_paths, spp - s0));
    const uint32_t paths = nj * ns;
    for (uint32_t n = 0; n < nj; ++n) {
      gpu::GpuJob g = jobs[j0 + n].gpu;
      g.data.w = uint32_t(jobs[j0 + n].rdm - r0);
      static_cast<gpu::GpuJob*>(b_jobs->mapped)[n] = g;
    }
    gpu::GpuPush push{glm::uvec4(nj, ns, s0, loop_budget)};
    ++info.batches;
    uint64_t dispatches = 0;
    for (bool first = true;; first = false) {
      if (options.cancel && options.cancel->load()) {
        cancelled = true;
        break;
      }
      std::memset(b_counters->mapped, 0, sizeof(gpu::GpuCounters));
      if (Status s = ctx.dispatch(*pipeline, push, paths, first ? b_paths : nullptr); !s) return s;
      ++dispatches;
      const gpu::GpuCounters counters = *static_cast<const gpu::GpuCounters*>(b_counters->mapped);
      rays += uint64_t(counters.values.y) + (uint64_t(counters.values.z) << 32);
      progress();
      if (counters.values.x == 0) break;
    }
    info.dispatches += dispatches;
    info.max_dispatches_per_batch = std::max(info.max_dispatches_per_batch, dispatches);
    if (cancelled) break;
    if (record) collectSets(r0, jobs[j0 + nj - 1].rdm);
    // Accumulate in job, then sample order (the CPU's order).
    const glm::vec4* out = static_cast<const glm::vec4*>(b_results->mapped);
    for (uint32_t n = 0; n < nj; ++n) {
      const Job& job = jobs[j0 + n];
      if (job.group != current_group) {
        finishGroup(current_group);
        current_group = job.group;
      }
      for (uint32_t s = 0; s < ns; ++s) {
        const glm::vec4 v = out[size_t(n) * ns + s];
        RDM_CHECK(v.w != gpu::kWeightWalkBoundExceeded && "the kernel's walk ran past its bound");
        estimator.add(vec3(v), v.w);
      }
    }
    s0 += ns;
    if (s0 >= spp) {
      for (uint32_t n = 0; n < nj; ++n) {
        if (--jobs_left[size_t(jobs[j0 + n].rdm)] == 0) ++rdms_done;
      }
      s0 = 0;
      j0 += nj;
    }
    progress();
  }
  if (!cancelled) finishGroup(current_group);
  if (record) {
    for (RdmData& rdm : result.rdms) sortUniqueSlots(rdm.full_set), sortUniqueSlots(rdm.first_set);
  }

  report.rdms = int(result.rdms.size());
  report.rays = rays;
  report.cancelled = cancelled;
  report.seconds = elapsed();
  summariseBake(result.rdms, report);
  if (options.info) *options.info = info;
  return result;
}

}  // namespace rdm::vkbake

#endif  // RDM_HAVE_VULKAN
