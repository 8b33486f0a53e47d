// A bake job's record: what to bake, its state and progress. Persisted as
// jobs/<id>/job.json and returned (with derived fields) by GET /v1/jobs/{id}.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "rdm/atlas/atlas.h"
#include "rdm/bake/rebake_selection.h"
#include "rdm/scene/scene.h"

namespace rdm {

enum class JobState { kQueued, kRunning, kSucceeded, kFailed, kCancelled };

const char* stateName(JobState s);
bool terminal(JobState s);

struct JobRecord {
  std::string id, scene_id, base_job;
  long long scene_version = 0;
  long long seq = 0;
  BakeSettings settings;
  BakeMode mode = BakeMode::kFull;
  // How the job's atlas.exr stores radiance (docs/spec.md section 4); the per-RDM store and
  // the deltas are float32 whatever it is.
  RadianceFormat radiance = RadianceFormat::kFloat32;
  // Samples per face of the job's face_light.bin (docs/spec.md section 3.2); 0: none.
  int face_light_spp = 0;
  // The job's RDMs are filtered by the cross-block denoiser before they are written
  // (rdm/bake/denoise.h, docs/denoise.md); its noise figures are then the filtered ones.
  bool denoise = false;
  // The admission estimate of the job's memory (rdm/bake_estimate.h); 0: none (a job
  // recorded before estimates).
  uint64_t memory_estimate = 0;
  JobState state = JobState::kQueued;
  std::string build;  // binary that bakes; exact bases need the same
  // Where the RDMs bake: "cpu", or "vulkan" on `device` (its name); exact bases need the
  // same backend and device (docs/spec.md section 8.4).
  std::string backend = "cpu", device;
  std::string error;
  double created = 0.0, started = 0.0, finished = 0.0;  // unix seconds, 0 = not yet
  bool cancel_requested = false;
  // Daemon processes that started preparing or baking this job and did not stop cleanly,
  // plus the one working on it now; saved before the work starts. JobManager::start
  // quarantines an unfinished job that reached 2 (two deaths on it) instead of resuming it.
  int runs_started = 0;
  // Filled when the job is planned.
  int rdms_scene = 0;      // RDMs of the target version
  int rdms_rebake = 0;     // RDMs this job bakes
  int rdms_copied = 0;     // copied from the base job
  int rdms_done = 0;       // of rdms_rebake
  int rdms_held_peak = 0;  // most RDMs whose texels the job held at once (set when it ends)
  int changed_slots = 0;
  bool dirty_all = false;
  uint64_t units_total = 0, units_done = 0, units_restored = 0;
  uint64_t texels_total = 0, texels_done = 0;  // work-weighted progress
  // The face light's exposed faces (face_light_spp paths each): the total is estimated when
  // the job is planned (every face of the scene for a job that bakes the light anew, 0 for one
  // that updates its base's) and set from the bake once it starts.
  uint64_t face_light_faces_total = 0, face_light_faces_done = 0;
  uint64_t rays = 0;
  // Over the texels of the RDMs this job baked (stderr / value, luminance), set when it
  // succeeds; as `rdm bake`'s bake_report.json. Negative: not measured.
  double mean_relative_error = -1.0, max_relative_error = -1.0;
  // Progressive incremental jobs publish a preview pass before the final one.
  int passes_total = 1, passes_done = 0;
  int preview_spp = 0;               // samples per texel of the preview pass; 0 without one
  std::vector<double> pass_seconds;  // per published pass: seconds after `created`
  double bake_seconds = 0.0;         // wall time spent in this job's units (sum over threads)
  double finalize_seconds = 0.0;     // atlas assembly and writing
  double denoise_seconds = 0.0;      // of finalize_seconds: the denoiser's
  std::string effects_simulated, effects_skipped;
};

// The persisted form (job.json) and its reader.
nlohmann::json jobToJson(const JobRecord& job);
bool jobFromJson(const nlohmann::json& j, JobRecord& job);
// The API form: jobToJson plus progress {fraction, eta_seconds, phase} and links. The
// fraction weighs the RDMs' texels (spp paths each) and the face light's faces
// (face_light_spp paths each) by their paths.
nlohmann::json jobStatusJson(const JobRecord& job, double now);

}  // namespace rdm
