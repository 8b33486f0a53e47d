#include "rdm/service/job.h"

#include <algorithm>

#include "rdm/scene/bake_settings_json.h"

namespace rdm {

using nlohmann::json;

const char* stateName(JobState s) {
  switch (s) {
    case JobState::kQueued:
      return "queued";
    case JobState::kRunning:
      return "running";
    case JobState::kSucceeded:
      return "succeeded";
    case JobState::kFailed:
      return "failed";
    case JobState::kCancelled:
      return "cancelled";
  }
  return "failed";
}

bool terminal(JobState s) {
  return s != JobState::kQueued && s != JobState::kRunning;
}

json jobToJson(const JobRecord& j) {
  return {
      {"id", j.id},
      {"scene", j.scene_id},
      {"scene_version", j.scene_version},
      {"seq", j.seq},
      {"mode", modeName(j.mode)},
      {"base_job", j.base_job.empty() ? json() : json(j.base_job)},
      {"settings", bakeSettingsToJson(j.settings)},
      {"radiance", radianceFormatName(j.radiance)},
      {"face_light", j.face_light_spp},
      {"denoise", j.denoise},
      {"memory_estimate_bytes", j.memory_estimate},
      {"state", stateName(j.state)},
      {"build", j.build},
      {"backend", j.backend},
      {"device", j.device.empty() ? json() : json(j.device)},
      {"error", j.error.empty() ? json() : json(j.error)},
      {"cancel_requested", j.cancel_requested},
      {"runs_started", j.runs_started},
      {"created", j.created},
      {"started", j.started},
      {"finished", j.finished},
      {"rdms",
       {{"scene", j.rdms_scene},
        {"rebaked", j.rdms_rebake},
        {"copied", j.rdms_copied},
        {"done", j.rdms_done},
        {"held_peak", j.rdms_held_peak}}},
      {"changed_slots", j.changed_slots},
      {"dirty_all", j.dirty_all},
      {"units", {{"total", j.units_total}, {"done", j.units_done}, {"restored", j.units_restored}}},
      {"texels", {{"total", j.texels_total}, {"done", j.texels_done}}},
      {"face_light_faces",
       {{"total", j.face_light_faces_total}, {"done", j.face_light_faces_done}}},
      {"rays", j.rays},
      {"noise", j.mean_relative_error < 0.0 ? json()
                                            : json{{"mean_relative_error", j.mean_relative_error},
                                                   {"max_relative_error", j.max_relative_error}}},
      {"passes",
       {{"total", j.passes_total},
        {"done", j.passes_done},
        {"preview_spp", j.preview_spp},
        {"published_seconds", j.pass_seconds}}},
      {"timings",
       {{"bake_unit_seconds", j.bake_seconds},
        {"finalize_seconds", j.finalize_seconds},
        {"denoise_seconds", j.denoise_seconds}}},
      {"effects", {{"simulated", j.effects_simulated}, {"skipped", j.effects_skipped}}}};
}

bool jobFromJson(const json& j, JobRecord& job) {
  try {
    job.id = j.at("id");
    job.scene_id = j.at("scene");
    job.scene_version = j.at("scene_version");
    job.seq = j.at("seq");
    if (!parseMode(j.at("mode").get<std::string>(), job.mode)) return false;
    job.base_job = j.at("base_job").is_null() ? "" : j.at("base_job").get<std::string>();
    // Jobs recorded before a setting existed take the table's legacy value (the estimator: naive).
    auto settings =
        readBakeSettings(j.at("settings"), {"settings", {}, BakeSettingsForm::kLegacyRecord});
    if (!settings) return false;
    job.settings = *settings;
    // Jobs recorded before the radiance format was a request key wrote float32.
    auto radiance = parseRadianceFormat(j.value("radiance", std::string("float32")));
    if (!radiance) return false;
    job.radiance = *radiance;
    job.face_light_spp = j.value("face_light", 0);  // absent before the daemon baked face light
    job.denoise = j.value("denoise", false);        // absent before the daemon denoised
    job.memory_estimate = j.value("memory_estimate_bytes", uint64_t(0));
    const std::string state = j.at("state");
    for (JobState st : {JobState::kQueued, JobState::kRunning, JobState::kSucceeded,
                        JobState::kFailed, JobState::kCancelled}) {
      if (state == stateName(st)) job.state = st;
    }
    job.build = j.at("build");
    job.backend = j.value("backend", std::string("cpu"));  // absent before the Vulkan daemon
    if (job.backend != "cpu" && job.backend != "vulkan") return false;
    job.device = j.value("device", json()).is_string() ? j.at("device").get<std::string>() : "";
    job.error = j.at("error").is_null() ? "" : j.at("error").get<std::string>();
    job.cancel_requested = j.at("cancel_requested");
    job.runs_started = j.value("runs_started", 0);  // absent before quarantine
    job.created = j.at("created"), job.started = j.at("started"), job.finished = j.at("finished");
    const json& r = j.at("rdms");
    job.rdms_scene = r.at("scene"), job.rdms_rebake = r.at("rebaked"),
    job.rdms_copied = r.at("copied");
    job.rdms_done = r.at("done");
    job.rdms_held_peak = r.value("held_peak", 0);
    job.changed_slots = j.at("changed_slots"), job.dirty_all = j.at("dirty_all");
    job.units_total = j.at("units").at("total"), job.units_done = j.at("units").at("done");
    job.units_restored = j.at("units").at("restored");
    job.texels_total = j.at("texels").at("total"), job.texels_done = j.at("texels").at("done");
    const json faces = j.value("face_light_faces", json::object());  // absent before 2026-12
    job.face_light_faces_total = faces.value("total", uint64_t(0));
    job.face_light_faces_done = faces.value("done", uint64_t(0));
    job.rays = j.at("rays");
    if (const json noise = j.value("noise", json()); noise.is_object()) {  // absent before 2026-12
      const auto figure = [&](const char* key) {
        return noise.contains(key) && noise[key].is_number() ? noise[key].get<double>() : -1.0;
      };
      job.mean_relative_error = figure("mean_relative_error");
      job.max_relative_error = figure("max_relative_error");
    }
    const json passes = j.value("passes", json::object());  // absent before progressive jobs
    job.passes_total = passes.value("total", 1), job.passes_done = passes.value("done", 0);
    job.preview_spp = passes.value("preview_spp", 0);
    job.pass_seconds = passes.value("published_seconds", std::vector<double>());
    job.bake_seconds = j.at("timings").at("bake_unit_seconds");
    job.finalize_seconds = j.at("timings").at("finalize_seconds");
    job.denoise_seconds = j.at("timings").value("denoise_seconds", 0.0);
    job.effects_simulated = j.at("effects").at("simulated");
    job.effects_skipped = j.at("effects").at("skipped");
    return true;
  } catch (const std::exception&) {
    return false;
  }
}

namespace {

double workFraction(const JobRecord& job) {
  if (job.state == JobState::kSucceeded) return 1.0;
  const double texel_paths = double(std::max(job.settings.spp, 1));
  const double face_paths = double(std::max(job.face_light_spp, 0));
  const double total =
      double(job.texels_total) * texel_paths + double(job.face_light_faces_total) * face_paths;
  const double done =
      double(job.texels_done) * texel_paths +
      double(std::min(job.face_light_faces_done, job.face_light_faces_total)) * face_paths;
  return total > 0.0 ? done / total : 0.0;
}

// What a running job does now: "preparing", "rdms", "face_light" or "results".
json runningPhase(const JobRecord& job) {
  if (job.state != JobState::kRunning) return json();
  if (job.rdms_scene == 0) return "preparing";  // set when the job is planned
  if (job.texels_done < job.texels_total) return "rdms";
  if (job.face_light_faces_done < job.face_light_faces_total) return "face_light";
  return "results";
}

}  // namespace

json jobStatusJson(const JobRecord& job, double now) {
  json j = jobToJson(job);
  j.erase("seq");
  const double fraction = workFraction(job);
  double elapsed = job.started > 0 ? (job.finished > 0 ? job.finished : now) - job.started : 0.0;
  json eta;  // null until 2 % is done
  if (job.state == JobState::kRunning && fraction > 0.02)
    eta = elapsed * (1.0 - fraction) / fraction;
  j["progress"] = {{"rdms_done", job.rdms_done},
                   {"rdms_total", job.rdms_rebake},
                   {"fraction", fraction},
                   {"elapsed_seconds", elapsed},
                   {"eta_seconds", eta},
                   {"phase", runningPhase(job)},
                   {"face_light_faces_done", job.face_light_faces_done},
                   {"face_light_faces_total", job.face_light_faces_total}};
  j["links"] = {{"self", "/v1/jobs/" + job.id}, {"scene", "/v1/scenes/" + job.scene_id}};
  if (job.state == JobState::kSucceeded) {
    const bool bc6h = job.radiance == RadianceFormat::kBc6h;
    j["links"]["atlas"] = "/v1/jobs/" + job.id + (bc6h ? "/atlas.ktx2" : "/atlas.exr");
    if (bc6h) j["links"]["depth"] = "/v1/jobs/" + job.id + "/depth.exr";
    j["links"]["index_json"] = "/v1/jobs/" + job.id + "/index.json";
    j["links"]["index_txt"] = "/v1/jobs/" + job.id + "/index.txt";
  }
  return j;
}

}  // namespace rdm
