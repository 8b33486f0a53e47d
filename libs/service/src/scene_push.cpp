#include "rdm/service/scene_push.h"

#include "rdm/scene/scene_patch.h"

namespace rdm {

using nlohmann::json;

Expected<ServerScene> fetchServerScene(BakeClient& client, const std::string& scene_id) {
  auto reply = client.get("/v1/scenes/" + scene_id);
  if (!reply) return reply.status();
  if (!reply->ok()) return httpErrorStatus(*reply);
  auto scene = parseSceneJson(reply->body);
  if (!scene)
    return Status::error("the server sent scene " + scene_id + " unreadable: " + scene.error());
  const std::string version = reply->header("X-Scene-Version");
  if (version.empty() || version.find_first_not_of("0123456789") != std::string::npos)
    return Status::error("the server sent scene " + scene_id + " without X-Scene-Version");
  return ServerScene{std::move(*scene), std::stoll(version)};
}

namespace {

Expected<ScenePushed> sent(Expected<json> answer) {
  if (!answer) return answer.status();
  const json& a = *answer;
  ScenePushed out;
  out.version = a.value("version", 0ll);
  out.dirty_all = a.value("dirty_all", false);
  if (a.contains("changed_slots") && a["changed_slots"].is_array())
    out.changed_slots = (long long)a["changed_slots"].size();
  if (a.contains("global_changes") && a["global_changes"].is_array())
    for (const json& g : a["global_changes"])
      if (g.is_string()) out.global_changes.push_back(g);
  out.changed = out.dirty_all || out.changed_slots > 0 || !out.global_changes.empty();
  return out;
}

}  // namespace

Expected<ScenePushed> pushScene(BakeClient& client, const std::string& scene_id,
                                const Scene& target) {
  auto current = fetchServerScene(client, scene_id);
  if (!current) return current.status();
  const json patch = makeScenePatch(current->scene, target, current->version);
  if (scenePatchIsEmpty(patch)) return ScenePushed{current->version};
  return sent(client.patchScene(scene_id, patch));
}

Expected<ScenePushed> pushPatch(BakeClient& client, const std::string& scene_id, json patch) {
  if (!patch.is_object()) return Status::invalidField("patch", "a PATCH document is an object");
  if (!patch.contains("base_version")) {
    auto current = fetchServerScene(client, scene_id);
    if (!current) return current.status();
    patch["base_version"] = current->version;
  }
  return sent(client.patchScene(scene_id, patch));
}

std::string describePush(const ScenePushed& pushed) {
  const std::string version = std::to_string(pushed.version);
  if (!pushed.changed) return "unchanged at version " + version;
  std::string out = "version " + version + ": ";
  out += pushed.dirty_all ? std::string("every slot re-lit")
                          : std::to_string(pushed.changed_slots) + " slot" +
                                (pushed.changed_slots == 1 ? "" : "s") + " changed";
  for (const std::string& g : pushed.global_changes) out += ", " + g;
  return out;
}

}  // namespace rdm
