// Vulkan compute backend of the RDM bake (include/rdm/vulkan_bake.h, docs/vulkan.md).
//
// Host side: the plan (RDMs, skipped faces, texel jobs), the exact central depths (on the
// CPU, exactCentralDepth: identical to the CPU backend) and the per-texel estimators (double,
// in texel then sample order, as the CPU accumulates) live here; the kernel
// (shaders/bake.comp) traces one path per invocation and writes (radiance, sample weight).
// Paths run in batches; a batch is dispatched again and again until no path is active (an
// invocation suspends its path before lavapipe's loop limit, docs/spec.md section 9).
#include "rdm/vulkan_bake.h"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstring>

#include "rdm/bake_stats.h"
#include "rdm/check.h"
#include "rdm/rdm_shared_cpp.h"
#include "rdm/traversal.h"

#if RDM_HAVE_VULKAN
#include <vulkan/vulkan.h>

#include "rdm_spirv.h"
#include "shared/rdm_gpu_layout.h"
#include "vulkan_context.h"
#endif

namespace rdm {

Expected<BakeBackend> parseBakeBackend(const std::string& text) {
  if (text == "cpu") return BakeBackend::kCpu;
  if (text == "vulkan") return BakeBackend::kVulkan;
  if (text == "auto") return BakeBackend::kAuto;
  return Status::error("unknown backend '" + text + "': expected cpu, vulkan or auto");
}

const char* bakeBackendName(BakeBackend backend) {
  switch (backend) {
    case BakeBackend::kCpu:
      return "cpu";
    case BakeBackend::kVulkan:
      return "vulkan";
    case BakeBackend::kAuto:
      return "auto";
  }
  return "?";
}

Expected<BakeResult> bakeSceneVulkan(const VoxelWorld& world, const BakeSettings& settings,
                                     const VulkanBakeOptions& options) {
  return bakeRdmsVulkan(world, settings, listRdms(world, settings), options);
}

#if !RDM_HAVE_VULKAN

bool vulkanBackendBuilt() {
  return false;
}
Expected<std::vector<VulkanDeviceInfo>> listVulkanDevices() {
  return Status::error("this build has no Vulkan backend (configured with -DRDM_VULKAN=OFF)");
}
Expected<BakeResult> bakeRdmsVulkan(const VoxelWorld&, const BakeSettings&,
                                    const std::vector<RdmId>&, const VulkanBakeOptions&) {
  return Status::error("this build has no Vulkan backend (configured with -DRDM_VULKAN=OFF)");
}
BackendChoice resolveBakeBackend(BakeBackend requested, const std::string&) {
  if (requested == BakeBackend::kAuto)
    return {BakeBackend::kCpu, "auto: this build has no Vulkan backend"};
  return {requested, "requested"};
}

#else

bool vulkanBackendBuilt() {
  return true;
}

namespace {

using glm::ivec3;
using glm::vec3;
using namespace vkbake;

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

}  // namespace

Expected<std::vector<VulkanDeviceInfo>> listVulkanDevices() {
  Instance instance;
  if (Status s = createInstance(instance); !s) return s;
  std::vector<VkPhysicalDevice> devices;
  std::vector<VulkanDeviceInfo> infos;
  if (Status s = enumerateVulkanDevices(instance.handle, devices, infos); !s) return s;
  return infos;
}

BackendChoice resolveBakeBackend(BakeBackend requested, const std::string& device) {
  if (requested != BakeBackend::kAuto)
    return {requested, std::string("requested --backend ") + bakeBackendName(requested)};
  auto devices = listVulkanDevices();
  if (!devices)
    return {BakeBackend::kCpu, "auto: no usable Vulkan (" + devices.error() + "), using the CPU"};
  auto index = selectVulkanDevice(*devices, device, QueueNeed::kCompute);
  if (!index) return {BakeBackend::kCpu, "auto: " + index.error() + ", using the CPU"};
  const VulkanDeviceInfo& d = (*devices)[size_t(*index)];
  if (d.type == "cpu") {
    return {BakeBackend::kCpu, "auto: the Vulkan device '" + d.name +
                                   "' is a CPU implementation, slower than the CPU baker on the "
                                   "same cores; using the CPU"};
  }
  return {BakeBackend::kVulkan, "auto: Vulkan device '" + d.name + "' (" + d.type + ")"};
}

Expected<BakeResult> bakeRdmsVulkan(const VoxelWorld& world, const BakeSettings& settings,
                                    const std::vector<RdmId>& rdms,
                                    const VulkanBakeOptions& options) {
  if (settings.estimator != Estimator::kNaive) {
    return Status::invalid(
        "settings.estimator",
        "the Vulkan bake has only the naive estimator (docs/spec.md section 3.1)");
  }
  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  if (settings.spp < 1) return Status::error("Vulkan bake: spp must be at least 1");
  if (world.size.x > 256 || world.size.y > 256 || world.size.z > 256) {
    return Status::error("Vulkan bake: the grid exceeds 256 slots per axis");
  }

  // --- Device, pipeline ---------------------------------------------------------------
  Context ctx;
  if (Status s = createInstance(ctx.instance); !s) return s;
  std::vector<VkPhysicalDevice> devices;
  std::vector<VulkanDeviceInfo> infos;
  if (Status s = enumerateVulkanDevices(ctx.instance.handle, devices, infos); !s) return s;
  auto index = selectVulkanDevice(infos, options.device, QueueNeed::kCompute);
  if (!index) return index.status();
  if (Status s = ctx.createDevice(*index, devices); !s) return s;
  BakeResult result;
  BakeReport& report = result.report;
  report.effects = sceneEffects(world);
  const bool sun = report.effects.sun || options.all_effects;
  const bool emit = report.effects.emitters || options.all_effects;
  if (Status s = ctx.createPipeline(sun, emit); !s) return s;

  // --- Scene buffers ------------------------------------------------------------------
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
  std::vector<gpu::GpuMaterial> materials(256);
  for (size_t p = 0; p < 256; ++p) {
    const Material& m = world.materials[p];
    materials[p].base_metallic = glm::vec4(m.base_color, m.metallic);
    materials[p].f0_alpha = glm::vec4(m.f0, m.alpha);
    materials[p].emission = glm::vec4(m.emission, 0.0f);
    materials[p].flags = glm::uvec4(m.emissive ? 1u : 0u, uint32_t(m.roughness), 0u, 0u);
  }
  // Palette bytes, four per word, then each block's 4^3 brick mask (brickEmpty in bake.comp).
  const size_t blocks = world.blocks.size();
  RDM_CHECK(world.occupancy.size() == blocks);
  std::vector<uint32_t> voxels(blocks * (1024 + 2), 0u);
  for (size_t b = 0; b < blocks; ++b) {
    for (size_t v = 0; v < 4096; ++v)
      voxels[b * 1024 + v / 4] |= uint32_t(world.blocks[b].voxels[v]) << (8 * (v % 4));
    voxels[blocks * 1024 + 2 * b] = uint32_t(world.occupancy[b].bricks);
    voxels[blocks * 1024 + 2 * b + 1] = uint32_t(world.occupancy[b].bricks >> 32);
  }
  std::vector<gpu::GpuEmitter> emitters;
  for (const Emitter& e : world.emitters.emitters)
    emitters.push_back({glm::ivec4(e.voxel, e.face), glm::vec4(e.radiance, 0.0f)});

  const uint32_t spp = uint32_t(settings.spp);
  const uint64_t budget_paths = std::max<uint64_t>(gpu::kWorkgroupSize, options.max_batch_paths);
  const uint64_t batch_paths = std::min<uint64_t>(
      budget_paths, ctx.props.limits.maxStorageBufferRange / sizeof(gpu::GpuPathState));
  const uint32_t max_jobs = uint32_t(std::max<uint64_t>(1, batch_paths / spp));
  const uint32_t loop_budget = std::clamp<uint32_t>(options.loop_budget, 256u, gpu::kMaxLoopBudget);

  Buffer* b_params;
  Buffer *b_slots, *b_voxels, *b_materials, *b_emitters, *b_cdf, *b_jobs, *b_paths, *b_results,
      *b_counters;
  {
    auto check = [](Expected<Buffer*> e, Buffer*& out) -> Status {
      if (!e) return e.status();
      out = *e;
      return {};
    };
    ctx.buffers.reserve(gpu::kBindingCount);
    Status s;
    if (s = check(ctx.createBuffer(sizeof(params), "parameter"), b_params); !s) return s;
    if (s = check(ctx.createBuffer(world.slots.size() * sizeof(int32_t), "slot grid"), b_slots); !s)
      return s;
    if (s = check(ctx.createBuffer(voxels.size() * sizeof(uint32_t), "voxel"), b_voxels); !s)
      return s;
    if (s = check(ctx.createBuffer(materials.size() * sizeof(gpu::GpuMaterial), "material"),
                  b_materials);
        !s)
      return s;
    if (s = check(ctx.createBuffer(emitters.size() * sizeof(gpu::GpuEmitter), "emitter"),
                  b_emitters);
        !s)
      return s;
    if (s = check(ctx.createBuffer(world.emitters.cdf.size() * sizeof(float), "emitter CDF"),
                  b_cdf);
        !s)
      return s;
    if (s = check(
            ctx.createBuffer(
                uint64_t(std::min<uint64_t>(max_jobs, batch_paths)) * sizeof(gpu::GpuJob), "job"),
            b_jobs);
        !s)
      return s;
    if (s = check(ctx.createBuffer(batch_paths * sizeof(gpu::GpuPathState), "path state"), b_paths);
        !s)
      return s;
    if (s = check(ctx.createBuffer(batch_paths * sizeof(glm::vec4), "result"), b_results); !s)
      return s;
    if (s = check(ctx.createBuffer(sizeof(gpu::GpuCounters), "counter"), b_counters); !s) return s;
  }
  std::memcpy(b_params->mapped, &params, sizeof(params));
  upload(b_slots, world.slots);
  upload(b_voxels, voxels);
  upload(b_materials, materials);
  upload(b_emitters, emitters);
  upload(b_cdf, world.emitters.cdf);
  ctx.bind({b_params, b_slots, b_voxels, b_materials, b_emitters, b_cdf, b_jobs, b_paths, b_results,
            b_counters});

  VulkanBakeInfo info;
  info.device = infos[size_t(*index)];
  info.setup_seconds = elapsed();

  // --- Plan: RDM images, skipped faces, texel jobs in (rdm, face, j, i) order -------------
  std::vector<Job> jobs;
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
          // Depth: the exact integer central ray, as the CPU backend computes it.
          const ivec3 d = shared::texelCentralDirection(i, j, S);
          const ivec3 dir = d.x * shared::faceTangent(f) + d.y * shared::faceBitangent(f) +
                            d.z * shared::faceNormal(f);
          const glm::ivec2 px = shared::rdmTexelPixel(0, 0, S, f, i, j);
          data.image.at(px.x, px.y, 3) = exactCentralDepth(world, origin, dir);
        }
    }
    result.rdms.push_back(std::move(data));
  }
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

  uint64_t rays = 0;
  bool cancelled = false;
  std::vector<glm::vec4> batch_results;
  auto progress = [&] {
    if (options.on_progress)
      options.on_progress({rdms_done, int(result.rdms.size()), rays, elapsed()});
  };
  size_t j0 = 0;
  uint32_t s0 = 0;
  while (j0 < jobs.size() && !cancelled) {
    const uint32_t nj = uint32_t(std::min<size_t>(max_jobs, jobs.size() - j0));
    const uint32_t ns =
        spp <= batch_paths ? spp : uint32_t(std::min<uint64_t>(batch_paths, spp - s0));
    const uint32_t paths = nj * ns;
    for (uint32_t n = 0; n < nj; ++n)
      static_cast<gpu::GpuJob*>(b_jobs->mapped)[n] = jobs[j0 + n].gpu;
    gpu::GpuPush push{glm::uvec4(nj, ns, s0, loop_budget)};
    ++info.batches;
    uint64_t dispatches = 0;
    for (bool first = true;; first = false) {
      if (options.cancel && options.cancel->load()) {
        cancelled = true;
        break;
      }
      std::memset(b_counters->mapped, 0, sizeof(gpu::GpuCounters));
      if (Status s = ctx.dispatch(push, paths, first ? b_paths : nullptr); !s) return s;
      ++dispatches;
      const gpu::GpuCounters counters = *static_cast<const gpu::GpuCounters*>(b_counters->mapped);
      rays += uint64_t(counters.values.y) + (uint64_t(counters.values.z) << 32);
      progress();
      if (counters.values.x == 0) break;
    }
    info.dispatches += dispatches;
    info.max_dispatches_per_batch = std::max(info.max_dispatches_per_batch, dispatches);
    if (cancelled) break;
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

  report.rdms = int(result.rdms.size());
  report.rays = rays;
  report.cancelled = cancelled;
  report.seconds = elapsed();
  summariseBake(result.rdms, report);
  if (options.info) *options.info = info;
  return result;
}

#endif  // RDM_HAVE_VULKAN

}  // namespace rdm
