// Route registration for the v1 API (docs/spec.md section 8); docs/api.md documents each route.
#pragma once

#include <optional>

#include <httplib.h>

#include "problem.h"
#include "rdm/atlas/bake_estimate.h"
#include "rdm/service/job_manager.h"
#include "rdm/service/metrics.h"
#include "rdm/service/scene_store.h"
#include "server_config.h"

namespace rdm::server {

struct ApiContext {
  const ServerConfig& config;
  SceneStore& scenes;
  JobManager& jobs;
  Metrics& metrics;
};

void registerSceneRoutes(httplib::Server& server, ApiContext& ctx);   // api_scenes.cpp
void registerJobRoutes(httplib::Server& server, ApiContext& ctx);     // api_jobs.cpp
void registerResultRoutes(httplib::Server& server, ApiContext& ctx);  // api_results.cpp

// limits.cpp: the server's configured limits, stricter than or equal to docs/spec.md section 2's.
// kInvalidInput naming the field over one of the server limits (422).
Status sceneWithinLimits(const Scene& scene, const ServerConfig& config);
Status checkSettingsLimits(const BakeSettings& s, const ServerConfig& config,
                           const std::string& prefix);
// Reads {"version", "settings", "mode", "base_job"} of POST /v1/scenes/{id}/bakes; a refusal
// is kInvalidInput naming the field.
// Admission (docs/api.md "Admission"): the refusal of an upload whose placements or smallest
// job exceed the limits (413), and of a job whose estimate exceeds max_job_memory (422, with
// the estimate's JSON in `estimate` either way).
std::optional<Problem> admitScene(const Scene& scene, const ServerConfig& config);
std::optional<Problem> admitJob(const Scene& scene, const SubmitRequest& request,
                                const ServerConfig& config, nlohmann::json& estimate);
nlohmann::json estimateJson(const BakeEstimate& estimate);
Problem sceneTooLarge(const std::string& detail);  // 413 scene-too-large, field placements

Expected<SubmitRequest> parseBakeRequest(const nlohmann::json& body, const Scene& current,
                                         const ServerConfig& config);

}  // namespace rdm::server
