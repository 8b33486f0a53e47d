#include "rdm/service/job_wire.h"

namespace rdm {

using nlohmann::json;

Expected<JobProgress> parseJobProgress(const json& j) {
  JobProgress p;
  try {
    p.id = j.at("id"), p.scene = j.at("scene"), p.mode = j.at("mode"), p.state = j.at("state");
    p.base_job = j.at("base_job").is_null() ? "" : j.at("base_job").get<std::string>();
    p.error = j.at("error").is_null() ? "" : j.at("error").get<std::string>();
    p.scene_version = j.at("scene_version");
    const json passes = j.value("passes", json::object());
    p.passes_total = passes.value("total", 1), p.passes_done = passes.value("done", 0);
    p.preview_spp = passes.value("preview_spp", 0);
    p.spp = j.at("settings").at("spp");
    const json& progress = j.at("progress");
    p.fraction = progress.at("fraction"), p.elapsed_seconds = progress.at("elapsed_seconds");
    if (!progress.at("eta_seconds").is_null()) p.eta_seconds = progress.at("eta_seconds");
    if (progress.contains("phase") && progress["phase"].is_string()) p.phase = progress["phase"];
    const json& rdms = j.at("rdms");
    p.rdms_scene = rdms.at("scene"), p.rdms_rebaked = rdms.at("rebaked"),
    p.rdms_done = rdms.at("done");
  } catch (const std::exception&) {
    return Status::invalid("job", "the daemon sent a job status without the expected fields");
  }
  return p;
}

}  // namespace rdm
