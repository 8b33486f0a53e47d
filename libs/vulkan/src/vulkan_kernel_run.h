// The bake kernel (shaders/bake.comp) over one scene: the scene's buffers bound in the
// kernel's descriptor set, and batches of (job, sample) paths dispatched until every path in
// them finished, each submission kept near the dispatch budget (dispatch_budget.h). The RDM
// bake (vulkan_bake_batches.cpp), the face light (vulkan_face_light.cpp) and reference renders
// (vulkan_render.cpp) run on it.
#pragma once

#if RDM_HAVE_VULKAN

#include <atomic>
#include <cstdint>
#include <functional>

#include "rdm/base/check.h"
#include "rdm/scene/world.h"
#include "rdm/vulkan/dispatch_budget.h"
#include "vulkan_context.h"

namespace rdm::vkbake {

// A finished path's result (radiance, sample weight): a walk past its bound is a kernel bug,
// never a miss (kWeightWalkBoundExceeded, rdm_gpu_layout.h).
inline void checkPathResult(const glm::vec4& v) {
  RDM_CHECK(v.w != gpu::kWeightWalkBoundExceeded && "the kernel's walk ran past its bound");
}

struct KernelConfig {
  bool sun = false, emitters = false;  // effect code compiled in
  bool record = false;                 // slot-set recording
  uint32_t spp = 1;                    // samples per job
  uint64_t set_owners = 1;             // slot-set owners a batch may need at most
  uint32_t max_batch_paths = 1u << 18;
  uint32_t loop_budget = gpu::kMaxLoopBudget;
  double max_dispatch_seconds = 0.5;
  gpu::GpuCamera camera{};  // a render's camera (camera jobs); zero in bakes
};

class KernelRun {
 public:
  // Creates and binds the buffers; `ctx` must outlive the run.
  static Expected<std::unique_ptr<KernelRun>> create(Context& ctx, const VoxelWorld& world,
                                                     const BakeSettings& settings,
                                                     const KernelConfig& config);

  // The texel jobs the next batch may hold (dispatch budget and buffer sizes).
  uint32_t maxJobs() const { return budget_.maxJobs(); }
  // Slot-set owners one batch holds at most (recording).
  uint64_t setOwners() const { return set_owners_; }
  // Paths (job samples) one batch holds at most.
  uint64_t batchPaths() const { return batch_paths_; }
  // Samples of a batch that starts at sample `s0` of its jobs.
  uint32_t samplesFrom(uint32_t s0) const;
  // Where the next batch's jobs go (at most maxJobs()).
  gpu::GpuJob* jobs() { return static_cast<gpu::GpuJob*>(jobs_->mapped); }

  // Runs the batch of `job_count` jobs, samples [s0, s0 + samples), dispatching until every
  // path finished; `on_dispatch` after each dispatch. False when `cancel` stopped it.
  Expected<bool> runBatch(uint32_t job_count, uint32_t samples, uint32_t s0,
                          const std::atomic<bool>* cancel,
                          const std::function<void()>& on_dispatch);
  // The finished batch's (radiance, sample weight), job-major.
  const glm::vec4* results() const { return static_cast<const glm::vec4*>(results_->mapped); }
  // The batch's slot-set words (recording; rdm_gpu_layout.h), cleared by the caller.
  uint32_t* slotSets() { return static_cast<uint32_t*>(sets_->mapped); }
  uint32_t setWords() const { return set_words_; }
  uint64_t ownerSetBytes() const { return (2 * uint64_t(set_words_) + 1) * sizeof(uint32_t); }

  uint64_t rays() const { return rays_; }
  // Adds batches, dispatches, the longest dispatch and the smallest loop budget to `info`.
  void addStats(VulkanBakeInfo& info) const;

 private:
  KernelRun(Context& ctx, const KernelConfig& config, uint32_t max_jobs);
  Status bindScene(const VoxelWorld& world, const BakeSettings& settings, uint64_t batch_paths);

  Context& ctx_;
  const KernelConfig config_;
  Buffers buffers_;
  VkPipeline pipeline_ = VK_NULL_HANDLE;
  Buffer *jobs_ = nullptr, *paths_ = nullptr, *results_ = nullptr, *counters_ = nullptr,
         *sets_ = nullptr;
  uint64_t batch_paths_ = 0, set_owners_ = 1;
  uint32_t set_words_ = 0;
  DispatchBudget budget_;
  uint64_t rays_ = 0, batches_ = 0, dispatches_ = 0, max_dispatches_per_batch_ = 0;
  double max_dispatch_seconds_ = 0.0;
  uint64_t min_loop_budget_;
};

}  // namespace rdm::vkbake

#endif  // RDM_HAVE_VULKAN
