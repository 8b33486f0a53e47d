// Bringing a daemon's scene to a scene held by a client (docs/api.md, PATCH): the difference
// as one PATCH built by makeScenePatch, so only the changed slots and globals travel and the
// server's version history and incremental bakes follow. Used by `rdm submit --scene-id` and
// `rdm patch`.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "rdm/base/status.h"
#include "rdm/scene/scene.h"
#include "rdm/service/client.h"

namespace rdm {

struct ServerScene {
  Scene scene;
  long long version = 0;
};

struct ScenePushed {
  long long version = 0;  // the scene's version after the push
  bool changed = false;   // false: the server already held `target`; no version was made
  long long changed_slots = 0;
  bool dirty_all = false;
  std::vector<std::string> global_changes;  // e.g. "sun", "bake"
};

// The scene's current version as the server holds it (GET /v1/scenes/{id}).
Expected<ServerScene> fetchServerScene(BakeClient& client, const std::string& scene_id);

// Sends the difference between the server's current scene and `target`, nothing when equal.
Expected<ScenePushed> pushScene(BakeClient& client, const std::string& scene_id,
                                const Scene& target);

// Sends a PATCH document as written by a user; a missing base_version is the current one.
Expected<ScenePushed> pushPatch(BakeClient& client, const std::string& scene_id,
                                nlohmann::json patch);

// "version 3: 2 slots changed, sun" / "unchanged at version 2".
std::string describePush(const ScenePushed& pushed);

}  // namespace rdm
