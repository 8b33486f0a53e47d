#if RDM_HAVE_VULKAN

#include "vulkan_kernel_run.h"

#include <algorithm>
#include <chrono>
#include <cstring>

#include "rdm/base/check.h"

namespace rdm::vkbake {
namespace {

using glm::ivec3;

// The slot-set buffer's size cap: a batch holds at most this many bytes of bitsets, so a
// large grid bakes fewer RDMs per batch (cut at an RDM boundary) rather than fail.
constexpr uint64_t kSlotSetBudgetBytes = uint64_t(64) << 20;

template <class T>
void upload(Buffer* b, const std::vector<T>& data) {
  if (!data.empty()) std::memcpy(b->mapped, data.data(), data.size() * sizeof(T));
}

gpu::GpuParams sceneParams(const VoxelWorld& world, const BakeSettings& settings,
                           const gpu::GpuCamera& camera) {
  gpu::GpuParams params{};
  params.camera = camera;
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

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

KernelRun::KernelRun(Context& ctx, const KernelConfig& config, uint32_t max_jobs)
    : ctx_(ctx),
      config_(config),
      buffers_(ctx),
      budget_(config.max_dispatch_seconds, config.loop_budget, max_jobs),
      min_loop_budget_(config.loop_budget) {}

Expected<std::unique_ptr<KernelRun>> KernelRun::create(Context& ctx, const VoxelWorld& world,
                                                       const BakeSettings& settings,
                                                       const KernelConfig& config) {
  RDM_CHECK(config.spp >= 1);
  if (hasGlass(world)) {
    return Status::invalidField("palette.transmission",
                                "glass is path traced on the CPU backend only; bake and render "
                                "this scene with --backend cpu");
  }
  KernelConfig c = config;
  c.loop_budget = std::clamp<uint32_t>(c.loop_budget, 256u, gpu::kMaxLoopBudget);
  const uint64_t budget_paths = std::max<uint64_t>(gpu::kWorkgroupSize, c.max_batch_paths);
  const uint64_t storage_range = ctx.props.limits.maxStorageBufferRange;
  const uint64_t batch_paths =
      std::min<uint64_t>(budget_paths, storage_range / sizeof(gpu::GpuPathState));
  const uint32_t max_jobs = uint32_t(std::max<uint64_t>(1, batch_paths / c.spp));
  std::unique_ptr<KernelRun> run(new KernelRun(ctx, c, max_jobs));
  auto pipeline = ctx.pipeline(c.sun, c.emitters, c.record);
  if (!pipeline) return pipeline.status();
  run->pipeline_ = *pipeline;
  if (Status s = run->bindScene(world, settings, batch_paths); !s) return s;
  return run;
}

Status KernelRun::bindScene(const VoxelWorld& world, const BakeSettings& settings,
                            uint64_t batch_paths) {
  batch_paths_ = batch_paths;
  const gpu::GpuParams params = sceneParams(world, settings, config_.camera);
  const std::vector<gpu::GpuMaterial> materials = sceneMaterials(world);
  const std::vector<uint32_t> voxels = sceneVoxels(world);
  std::vector<gpu::GpuEmitter> emitters;
  for (const Emitter& e : world.emitters.emitters)
    emitters.push_back({glm::ivec4(e.voxel, e.face), glm::vec4(e.radiance, 0.0f)});
  // Slot sets: 2W + 1 words per owner of a batch; a batch holds at most set_owners_ owners.
  set_words_ = uint32_t((world.slots.size() + 31) / 32);
  const uint64_t storage_range = ctx_.props.limits.maxStorageBufferRange;
  set_owners_ = std::min<uint64_t>(
      {std::max<uint64_t>(1, std::min(kSlotSetBudgetBytes, storage_range) / ownerSetBytes()),
       std::max<uint64_t>(1, config_.set_owners), budget_.maxJobs()});
  std::vector<Buffer*> bound;
  // In binding order (rdm_gpu_layout.h).
  const std::pair<uint64_t, const char*> sizes[gpu::kBindingCount] = {
      {sizeof(params), "parameter"},
      {world.slots.size() * sizeof(int32_t), "slot grid"},
      {voxels.size() * sizeof(uint32_t), "voxel"},
      {materials.size() * sizeof(gpu::GpuMaterial), "material"},
      {emitters.size() * sizeof(gpu::GpuEmitter), "emitter"},
      {world.emitters.cdf.size() * sizeof(float), "emitter CDF"},
      {std::min<uint64_t>(budget_.maxJobs(), batch_paths) * sizeof(gpu::GpuJob), "job"},
      {batch_paths * sizeof(gpu::GpuPathState), "path state"},
      {batch_paths * sizeof(glm::vec4), "result"},
      {sizeof(gpu::GpuCounters), "counter"},
      {config_.record ? set_owners_ * ownerSetBytes() : 16, "slot-set"},
      {world.emitters.slot_first.size() * sizeof(uint32_t), "slot emitter"}};
  for (const auto& [bytes, what] : sizes) {
    auto b = buffers_.create(bytes, what);
    if (!b) return b.status();
    bound.push_back(*b);
  }
  jobs_ = bound[gpu::kBindingJobs];
  paths_ = bound[gpu::kBindingPaths];
  results_ = bound[gpu::kBindingResults];
  counters_ = bound[gpu::kBindingCounters];
  sets_ = bound[gpu::kBindingSlotSets];
  std::memcpy(bound[gpu::kBindingParams]->mapped, &params, sizeof(params));
  upload(bound[gpu::kBindingSlots], world.slots);
  upload(bound[gpu::kBindingVoxels], voxels);
  upload(bound[gpu::kBindingMaterials], materials);
  upload(bound[gpu::kBindingEmitters], emitters);
  upload(bound[gpu::kBindingEmitterCdf], world.emitters.cdf);
  upload(bound[gpu::kBindingSlotEmitters], world.emitters.slot_first);
  std::memset(sets_->mapped, 0, sets_->size);
  ctx_.bind(bound, ctx_.descriptor_set);
  return {};
}

uint32_t KernelRun::samplesFrom(uint32_t s0) const {
  const uint32_t spp = config_.spp;
  return spp <= batch_paths_ ? spp : uint32_t(std::min<uint64_t>(batch_paths_, spp - s0));
}

Expected<bool> KernelRun::runBatch(uint32_t job_count, uint32_t samples, uint32_t s0,
                                   const std::atomic<bool>* cancel,
                                   const std::function<void()>& on_dispatch) {
  RDM_CHECK(job_count >= 1 && uint64_t(job_count) * samples <= batch_paths_);
  ++batches_;
  uint64_t dispatches = 0;
  for (bool first = true;; first = false) {
    if (cancel && cancel->load()) return false;
    std::memset(counters_->mapped, 0, sizeof(gpu::GpuCounters));
    const gpu::GpuPush push{glm::uvec4(job_count, samples, s0, budget_.loopBudget())};
    min_loop_budget_ = std::min<uint64_t>(min_loop_budget_, budget_.loopBudget());
    const auto dispatched = std::chrono::steady_clock::now();
    if (Status s = ctx_.dispatch(pipeline_, push, job_count * samples, first ? paths_ : nullptr,
                                 ctx_.descriptor_set);
        !s)
      return s;
    const double took = secondsSince(dispatched);
    budget_.observe(took);
    max_dispatch_seconds_ = std::max(max_dispatch_seconds_, took);
    ++dispatches, ++dispatches_;
    const gpu::GpuCounters counters = *static_cast<const gpu::GpuCounters*>(counters_->mapped);
    rays_ += uint64_t(counters.values.y) + (uint64_t(counters.values.z) << 32);
    if (on_dispatch) on_dispatch();
    if (counters.values.x == 0) break;
  }
  max_dispatches_per_batch_ = std::max(max_dispatches_per_batch_, dispatches);
  return true;
}

void KernelRun::addStats(VulkanBakeInfo& info) const {
  info.batches += batches_;
  info.dispatches += dispatches_;
  info.max_dispatches_per_batch =
      std::max(info.max_dispatches_per_batch, max_dispatches_per_batch_);
  info.max_dispatch_seconds = std::max(info.max_dispatch_seconds, max_dispatch_seconds_);
  info.min_loop_budget = info.min_loop_budget == 0
                             ? min_loop_budget_
                             : std::min(info.min_loop_budget, min_loop_budget_);
}

}  // namespace rdm::vkbake

#endif  // RDM_HAVE_VULKAN
