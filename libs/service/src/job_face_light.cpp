// A daemon job's face light (docs/spec.md sections 3.2 and 8.4): baked after the job's RDMs
// into its output directory. An incremental job whose base has a face light of the same
// samples and settings updates the base's (updateFaceLight: the slots the edit changed and
// the neighbours whose exposed faces changed), as an edit in the viewer does; any other job
// bakes every slot. Either gives the bits the same call gives in one process.
#include <optional>

#include "job_finisher.h"
#include "rdm/bake/face_light.h"
#include "rdm/bake/shard.h"

namespace rdm {
namespace {

// The base's face light and the world it was baked for, when the job can update them.
struct UpdatableBase {
  FaceLight light;
  VoxelWorld world;
};

}  // namespace

Status JobFinisher::writeJobFaceLight(const ActiveJob& job, const JobRecord& record,
                                      const std::optional<JobRecord>& base,
                                      const FaceLightProgressFn& on_progress) {
  if (record.face_light_spp <= 0) return {};
  try {
    return bakeJobFaceLight(job, record, base, on_progress);
  } catch (const std::exception& e) {
    return jobFailure(e, "baking the face light");
  }
}

Status JobFinisher::bakeJobFaceLight(const ActiveJob& job, const JobRecord& record,
                                     const std::optional<JobRecord>& base_record,
                                     const FaceLightProgressFn& on_progress) {
  std::optional<UpdatableBase> base;
  if (record.mode != BakeMode::kFull) {
    auto base_scene = base_record ? scenes_.get(record.scene_id, base_record->scene_version)
                                  : std::shared_ptr<const Scene>();
    if (base_record && base_scene && base_record->face_light_spp == record.face_light_spp &&
        base_record->settings == record.settings) {
      auto light = readFaceLight(store_.outDir(record.base_job) + "/" + kFaceLightFile);
      if (light) base = UpdatableBase{std::move(*light), buildWorld(*base_scene)};
    }
  }
  // On the job's own backend, so a resumed job bakes the bits it started with.
  CpuFaceLightTracer cpu(threads_);
  FaceLightTracer& tracer = record.backend == "vulkan" && device_tracer_
                                ? static_cast<FaceLightTracer&>(*device_tracer_)
                                : cpu;
  FaceLight light;
  if (base) {
    light = std::move(base->light);
    auto updated =
        updateFaceLightOn(tracer, base->world, *job.world, record.settings, light, &job.abort);
    if (!updated) return updated.status();
    if (on_progress) on_progress(FaceLightProgress{});  // nothing left to count
    light.scene_digest = faceLightSceneDigest(*job.scene);
  } else {
    FaceLightOptions options;
    options.threads = threads_;
    options.spp = record.face_light_spp;
    options.settings = record.settings;
    options.stop = &job.abort;
    options.on_progress = on_progress;
    auto baked = bakeFaceLightOn(tracer, *job.world, *job.scene, options);
    if (!baked) return baked.status();
    light = std::move(*baked);
  }
  if (job.abort) return abortedStatus(job, "baking the face light");  // `light` is partial
  return writeFaceLight(store_.outDir(job.id) + "/" + kFaceLightFile, light);
}

}  // namespace rdm
