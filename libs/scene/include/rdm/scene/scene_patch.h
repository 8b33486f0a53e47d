// The PATCH format of a scene (docs/spec.md, "Scene patches"): {base_version, blocks,
// palette, edits, sun, sky, emission_scale, ambient, bake, size}. One implementation used by
// the daemon (apply), the viewer and the CLI (make). The patched document goes through the
// scene loader, so every range and reference check and its messages are the upload's.
#pragma once

#include <nlohmann/json.hpp>

#include "rdm/base/status.h"
#include "rdm/scene/scene.h"

namespace rdm {

// `patch` is the whole request body; base_version is checked by the caller. Returns the new
// scene, or an kInvalidInput Status naming the offending field.
Expected<Scene> applyScenePatch(const Scene& current, const nlohmann::json& patch);

// The PATCH body taking `from` (the server's scene at `base_version`) to `to`: new or
// redefined blocks, changed or appended palette entries, one edit per changed slot, and
// every changed global (sun, sky, emission_scale, ambient, bake settings, size). Blocks are
// never deleted (an unused block is harmless). applyScenePatch(from, patch) == to.
nlohmann::json makeScenePatch(const Scene& from, const Scene& to, long long base_version);

// Only base_version: the patch changes nothing.
bool scenePatchIsEmpty(const nlohmann::json& patch);

}  // namespace rdm
