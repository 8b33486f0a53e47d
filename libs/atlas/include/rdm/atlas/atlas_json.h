// The JSON form of an atlas entry (docs/spec.md section 4), shared by index.json, the atlas
// delta header and the daemon's delta listing:
//   {"slot": [i, j, k], "level": l, "size": S, "faces": [[page, x, y] or null, x 6]}
#pragma once

#include <nlohmann/json.hpp>

#include "rdm/atlas/atlas.h"

namespace rdm {

nlohmann::json atlasEntryJson(const AtlasEntry& e);
// Throws nlohmann::json::exception on a missing or mistyped field; callers catch at their
// boundary. Whether the tiles lie inside the pages is tilesFit's question.
AtlasEntry atlasEntryOf(const nlohmann::json& j);

}  // namespace rdm
