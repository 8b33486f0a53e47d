// Scene routes: POST /v1/scenes, GET /v1/scenes, GET / PATCH / DELETE /v1/scenes/{id},
// POST /v1/scenes/{id}/bakes, DELETE /v1/scenes/{id}/versions/{n}.
#include <algorithm>
#include <chrono>
#include <cstdio>

#include "api.h"
#include "http_util.h"
#include "rdm/base/log.h"
#include "rdm/scene/world.h"
#include "rdm/service/resource_id.h"
#include "status_problem.h"

namespace rdm::server {
namespace {

using nlohmann::json;

json changedSlotsJson(const SceneDiff& diff) {
  json slots = json::array();
  for (const glm::ivec3& s : diff.changed_slots) slots.push_back({s.x, s.y, s.z});
  return {{"changed_slots", slots},
          {"dirty_all", diff.dirty_all},
          {"global_changes", diff.global_changes}};
}

std::optional<Problem> postScene(ApiContext& ctx, const httplib::Request& req,
                                 httplib::Response& res) {
  // One linear pass with the depth limit and memory budget (rdm/base/json_parse.h).
  Expected<Scene> scene = parseSceneJson(req.body);
  if (!scene) return problemOf(scene.status());
  if (Status s = sceneWithinLimits(*scene, ctx.config); !s) return problemOf(s);
  // Before the world is built: a scene too large for any job here is refused (413).
  if (auto refused = admitScene(*scene, ctx.config)) return refused;
  if (ctx.scenes.count() >= size_t(ctx.config.max_scenes)) {
    return Problem{
        429,
        "too-many-scenes",
        "Too many scenes",
        "this server holds its limit of " + std::to_string(ctx.config.max_scenes) + " scenes",
        {}};
  }
  const std::array<int, 3> size = scene->size;
  auto created = ctx.scenes.create(std::move(*scene));
  if (!created) return problemOf(created.status());
  const SceneInfo& info = *created;
  const std::shared_ptr<const Scene> stored = ctx.scenes.get(info.id, 1);
  if (!stored) return internalError();
  json j = sceneInfoJson(info);
  const VoxelWorld world = buildWorld(*stored);
  j["rdms"] = countRdms(world);
  j["size"] = size;
  // What a job at the scene's own settings would take (POST .../bakes admits by it).
  j["estimate"] = estimateJson(
      estimateBake(world, stored->bake, RadianceFormat::kFloat32, std::max(1, ctx.config.threads)));
  res.set_header("Location", "/v1/scenes/" + info.id);
  res.set_header("ETag", "\"" + std::to_string(info.version) + "\"");
  sendJson(res, j, 201);
  return std::nullopt;
}

std::optional<Problem> listScenes(ApiContext& ctx, const httplib::Request& req,
                                  httplib::Response& res) {
  json items = json::array();
  for (const SceneInfo& info : ctx.scenes.list()) items.push_back(sceneInfoJson(info));
  json j = {{"scenes", items}};
  const std::string text = j.dump(1) + "\n";
  if (handleEtag(req, res, bodyEtag(text))) return std::nullopt;
  res.set_content(text, "application/json");
  return std::nullopt;
}

// Version v of scene id: 404 once pruned, 500 (logged) when kept but unreadable.
std::variant<std::shared_ptr<const Scene>, Problem> keptScene(ApiContext& ctx,
                                                              const std::string& id, long long v) {
  auto scene = ctx.scenes.find(id, v);
  if (!scene && scene.status().code() == StatusCode::kCorrupt) {  // logged by the store
    return corruptData("scene " + id + " version " + std::to_string(v) +
                       " is damaged on disk (fails its checksum or is cut short); the scene's "
                       "other versions are unaffected");
  }
  if (!scene && scene.status().code() != StatusCode::kNotFound) {
    logEvent(LogLevel::kError, "request_error", {{"message", scene.status().message()}});
    return internalError();
  }
  if (!scene) {
    return notFound("scene " + id + " version " + std::to_string(v) +
                    " is no longer kept: the newest " + std::to_string(ctx.scenes.keptVersions()) +
                    " versions and those jobs need are (docs/spec.md section 8.3)");
  }
  return *scene;
}

std::optional<Problem> getScene(ApiContext& ctx, const httplib::Request& req,
                                httplib::Response& res) {
  const std::string id = req.matches[1];
  auto info = validId(id, 's') ? ctx.scenes.info(id) : std::nullopt;
  if (!info) return notFound("no scene '" + id + "'");
  auto version = queryInt(req, "version", 1, info->version);
  if (auto* p = std::get_if<Problem>(&version)) return *p;
  const long long v = std::get<std::optional<long long>>(version).value_or(info->version);
  auto scene = keptScene(ctx, id, v);
  if (auto* p = std::get_if<Problem>(&scene)) return *p;
  const auto& kept = std::get<std::shared_ptr<const Scene>>(scene);
  res.set_header("X-Scene-Version", std::to_string(v));
  if (handleEtag(req, res, "\"" + std::to_string(v) + "\"")) return std::nullopt;
  res.set_content(sceneToJson(*kept), "application/json");
  return std::nullopt;
}

std::optional<Problem> patchScene(ApiContext& ctx, const httplib::Request& req,
                                  httplib::Response& res) {
  const std::string id = req.matches[1];
  if (!validId(id, 's') || !ctx.scenes.info(id)) return notFound("no scene '" + id + "'");
  auto body = parseJsonBody(req.body);
  if (!body) return problemOf(body.status());
  auto check = [&](const Scene& s) {
    if (Status within = sceneWithinLimits(s, ctx.config); !within) return within;
    const std::optional<Problem> refused = admitScene(s, ctx.config);
    return refused ? Status::error(StatusCode::kTooLarge, refused->detail, refused->field)
                   : Status();
  };
  auto out = ctx.scenes.patch(id, *body, check);
  if (!out && out.status().code() == StatusCode::kTooLarge && out.status().field() == "placements")
    return sceneTooLarge(out.status().message());
  if (!out) return problemOf(out.status());
  const PatchOutcome& o = *out;
  ctx.scenes.prune(id, ctx.jobs.versionsInUse(id));
  json j = sceneInfoJson(o.info);
  j.update(changedSlotsJson(o.diff));
  res.set_header("ETag", "\"" + std::to_string(o.info.version) + "\"");
  sendJson(res, j);
  return std::nullopt;
}

std::optional<Problem> postBake(ApiContext& ctx, const httplib::Request& req,
                                httplib::Response& res) {
  const std::string id = req.matches[1];
  auto info = validId(id, 's') ? ctx.scenes.info(id) : std::nullopt;
  if (!info) return notFound("no scene '" + id + "'");
  auto parsed = parseJsonBody(req.body);
  if (!parsed) return problemOf(parsed.status());
  const json& body = *parsed;
  long long version = info->version;
  if (body.is_object() && body.contains("version") && body["version"].is_number_integer()) {
    version = body["version"].get<long long>();
    if (version < 1 || version > info->version) {
      return invalidField(
          "field 'version': the scene has versions 1.." + std::to_string(info->version), "version");
    }
  }
  auto found = keptScene(ctx, id, version);
  if (auto* p = std::get_if<Problem>(&found)) return *p;
  const auto& scene = std::get<std::shared_ptr<const Scene>>(found);
  auto request = parseBakeRequest(body, *scene, ctx.config);
  if (!request) return problemOf(request.status());
  SubmitRequest& r = *request;
  r.scene_id = id;
  r.version = version;
  json estimate;
  if (auto refused = admitJob(*scene, r, ctx.config, estimate)) return refused;
  r.memory_estimate = estimate.value("memory_bytes", uint64_t(0));
  auto job = ctx.jobs.submit(r);
  if (!job) {
    if (job.status().code() == StatusCode::kBusy) res.set_header("Retry-After", "5");
    return problemOf(job.status());
  }
  const JobRecord& record = *job;
  res.set_header("Location", "/v1/jobs/" + record.id);
  res.set_header("Retry-After", "1");
  const double now =
      std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
  json reply = jobStatusJson(record, now);
  reply["estimate"] = std::move(estimate);
  sendJson(res, reply, 202);
  return std::nullopt;
}

// DELETE /v1/scenes/{id}[?jobs=delete]: the scene and every version (204); 409 while one of
// its jobs is unfinished, or while finished ones are kept and ?jobs=delete is absent.
std::optional<Problem> deleteScene(ApiContext& ctx, const httplib::Request& req,
                                   httplib::Response& res) {
  const std::string id = req.matches[1];
  if (!validId(id, 's') || !ctx.scenes.info(id)) return notFound("no scene '" + id + "'");
  bool with_jobs = false;
  if (req.has_param("jobs")) {
    if (req.get_param_value("jobs") != "delete")
      return badRequest("query parameter 'jobs' must be 'delete'", "jobs");
    with_jobs = true;
  }
  if (Status s = ctx.jobs.removeScene(id, with_jobs); !s) return problemOf(s);
  res.status = 204;
  return std::nullopt;
}

// DELETE /v1/scenes/{id}/versions/{n}: one older version (204); 404 unknown or already gone,
// 409 for the current version or one a job needs (JobManager::versionsInUse).
std::optional<Problem> deleteSceneVersion(ApiContext& ctx, const httplib::Request& req,
                                          httplib::Response& res) {
  const std::string id = req.matches[1], text = req.matches[2];
  if (!validId(id, 's') || !ctx.scenes.info(id)) return notFound("no scene '" + id + "'");
  long long version = 0;
  if (text.empty() || text.size() > 15 ||
      text.find_first_not_of("0123456789") != std::string::npos || (version = std::stoll(text)) < 1)
    return notFound("scene " + id + " has no version '" + text + "'");
  if (Status s = ctx.jobs.removeSceneVersion(id, version); !s) return problemOf(s);
  res.status = 204;
  return std::nullopt;
}

}  // namespace

void registerSceneRoutes(httplib::Server& server, ApiContext& ctx) {
  ApiContext* c = &ctx;
  server.Post("/v1/scenes",
              wrap([c](const auto& req, auto& res) { return postScene(*c, req, res); }));
  server.Get("/v1/scenes",
             wrap([c](const auto& req, auto& res) { return listScenes(*c, req, res); }));
  server.Get(R"(/v1/scenes/([^/]+))",
             wrap([c](const auto& req, auto& res) { return getScene(*c, req, res); }));
  server.Patch(R"(/v1/scenes/([^/]+))",
               wrap([c](const auto& req, auto& res) { return patchScene(*c, req, res); }));
  server.Post(R"(/v1/scenes/([^/]+)/bakes)",
              wrap([c](const auto& req, auto& res) { return postBake(*c, req, res); }));
  server.Delete(R"(/v1/scenes/([^/]+))",
                wrap([c](const auto& req, auto& res) { return deleteScene(*c, req, res); }));
  server.Delete(R"(/v1/scenes/([^/]+)/versions/([^/]+))",
                wrap([c](const auto& req, auto& res) { return deleteSceneVersion(*c, req, res); }));
}

}  // namespace rdm::server
