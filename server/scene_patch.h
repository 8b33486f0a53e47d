// PATCH /v1/scenes/{id} (SPEC section 8): applies {blocks, palette, edits, sun, sky,
// emission_scale, ambient, bake} to a scene. The patched document goes through the scene
// loader, so every range and reference check and its messages are the upload's.
#pragma once

#include <variant>

#include <nlohmann/json.hpp>

#include "problem.h"
#include "rdm/scene.h"

namespace rdm::server {

// `patch` is the whole request body; base_version is checked by the caller.
// Returns the new scene, or a 422 naming the offending field.
std::variant<Scene, Problem> applyScenePatch(const Scene& current, const nlohmann::json& patch);

}  // namespace rdm::server
