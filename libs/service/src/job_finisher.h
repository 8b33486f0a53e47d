// Finishing a job: the passes it publishes while it runs (PublishedPass, which clients read
// before its files exist) and, once its last unit landed, its results written to its output
// directory (the job's own per-RDM store, the atlas with the RDMs copied from its base, the
// face light, rdms.bin). Stateless between jobs; runs outside JobManager's lock, on the
// job's phase thread.
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "active_job.h"
#include "rdm/bake/face_light.h"
#include "rdm/service/job_manager.h"
#include "rdm/vulkan/vulkan_bake.h"
#include "rdm/vulkan/vulkan_bc6h.h"
#include "rdm/vulkan/vulkan_denoise.h"

namespace rdm {

using FaceLightProgressFn = std::function<void(const FaceLightProgress&)>;

class JobFinisher {
 public:
  // `threads`: the face light's (JobManagerOptions::threads; 0: all cores).
  JobFinisher(SceneStore& scenes, JobStore& store, int threads)
      : scenes_(scenes), store_(store), threads_(threads) {}

  // Writes a job's results from its spill and the base's stores. `base`: the base job's
  // record of an incremental job (its face light may be updated instead of baked anew).
  // Consumes job.records. Once job.abort is set it returns kCancelled between its writes and
  // from within the face light (its files then are partial; the caller removes them).
  // `on_face_light` (may be empty) sees the face light's progress as FaceLightOptions'
  // on_progress does; an update of the base's light reports its faces as done at once.
  Status finalize(ActiveJob& job, const JobRecord& record, const std::optional<JobRecord>& base,
                  const FaceLightProgressFn& on_face_light = {});
  // The device that bakes the face light of jobs recorded with backend "vulkan" (the
  // daemon's VulkanBaker, shared with its unit worker); unset: every face light on the CPU.
  // With `passes`, such jobs also encode a bc6h atlas and denoise on that device (its
  // index), through programs of their own created at first use.
  void useDevice(VulkanBaker& baker, bool passes) {
    device_tracer_.emplace(baker);
    if (passes) device_ = std::to_string(baker.device().index);
  }

 private:
  // Writes the job's face_light.bin when it asked for one (job_face_light.cpp).
  Status writeJobFaceLight(const ActiveJob& job, const JobRecord& record,
                           const std::optional<JobRecord>& base,
                           const FaceLightProgressFn& on_progress);
  Status bakeJobFaceLight(const ActiveJob& job, const JobRecord& record,
                          const std::optional<JobRecord>& base,
                          const FaceLightProgressFn& on_progress);  // may throw

  // The BC6H encoder and the denoiser of a job recorded with backend "vulkan" on the daemon's
  // device (job_device_passes.cpp): created at first use, one job's call at a time; empty or
  // null (the CPU, with the same blocks and, within 1e-5, the same texels) for other jobs or
  // when the device refuses to make them (logged).
  Bc6hEncodeFn bc6hEncoderFor(const JobRecord& record);
  std::unique_ptr<DenoiseDevice> denoiserFor(const JobRecord& record);

  SceneStore& scenes_;
  JobStore& store_;
  int threads_;
  std::optional<VulkanFaceLightTracer> device_tracer_;
  std::string device_;  // the Vulkan device's index; empty: none
  std::shared_ptr<std::mutex> device_mutex_ = std::make_shared<std::mutex>();
  std::shared_ptr<VulkanBc6hEncoder> bc6h_;
  std::shared_ptr<VulkanDenoiser> denoiser_;
};

// Pass `pass` of a running job as clients fetch it: a preview's texels in `own`, the final
// pass's in the job's `spill`.
// kCancelled for a phase of `job` that stopped at `step` on its abort flag.
Status abortedStatus(const ActiveJob& job, const char* step);

std::shared_ptr<PublishedPass> makePublishedPass(const ActiveJob& job, int pass,
                                                 const BakeSettings& settings,
                                                 std::map<RdmKey, Image> own,
                                                 std::shared_ptr<const RdmSpill> spill);

}  // namespace rdm
