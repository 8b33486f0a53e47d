// The daemon's job status as a client reads it (docs/api.md, "Jobs"): the typed view used by
// the viewer, `rdm status / fetch` and the daemon's tests instead of raw JSON lookups.
#pragma once

#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "rdm/base/status.h"

namespace rdm {

struct JobProgress {
  std::string id, scene, mode, state, base_job, error;
  long long scene_version = 0;
  int passes_total = 1, passes_done = 0;
  int preview_spp = 0;  // samples per texel of the preview pass, 0 without one
  int spp = 0;          // of the final pass
  double fraction = 0.0, elapsed_seconds = 0.0;
  std::optional<double> eta_seconds;  // absent until it means something
  // While running: "preparing", "rdms", "face_light" or "results"; empty otherwise (and
  // from daemons before the field).
  std::string phase;
  int rdms_scene = 0, rdms_rebaked = 0, rdms_done = 0;
  bool terminal() const { return state != "queued" && state != "running"; }
  bool succeeded() const { return state == "succeeded"; }
};

// Refuses (kInvalidInput naming the field) a status without the fields above.
Expected<JobProgress> parseJobProgress(const nlohmann::json& j);

}  // namespace rdm
