#include "scene_patch.h"

#include <map>

namespace rdm::server {
namespace {

using nlohmann::json;

constexpr const char* kPatchKeys[] = {"base_version", "blocks",         "palette", "edits", "sun",
                                      "sky",          "emission_scale", "ambient", "bake"};

std::optional<Problem> checkPatchKeys(const json& patch) {
  if (!patch.is_object()) return invalidField("the PATCH body must be a JSON object");
  for (auto it = patch.begin(); it != patch.end(); ++it) {
    bool known = false;
    for (const char* k : kPatchKeys) known = known || it.key() == k;
    if (!known) return invalidField("field '" + it.key() + "': unknown key", it.key());
  }
  return std::nullopt;
}

// "palette": {"<index>": entry}; an index replaces an entry or appends right after the end.
std::optional<Problem> patchPalette(const json& palette, json& doc) {
  if (!palette.is_object())
    return invalidField("field 'palette': expected an object keyed by index", "palette");
  std::map<int, const json*> by_index;
  for (auto it = palette.begin(); it != palette.end(); ++it) {
    const std::string& key = it.key();
    char* end = nullptr;
    long index = std::strtol(key.c_str(), &end, 10);
    if (key.empty() || *end || index < 1 || index > 255) {
      return invalidField("field 'palette." + key + "': index must be an integer in 1..255",
                          "palette." + key);
    }
    by_index[int(index)] = &it.value();
  }
  json& list = doc["palette"];
  for (const auto& [index, entry] : by_index) {
    if (size_t(index) <= list.size()) {
      list[size_t(index) - 1] = *entry;
    } else if (size_t(index) == list.size() + 1) {
      list.push_back(*entry);
    } else {
      const std::string f = "palette." + std::to_string(index);
      return invalidField("field '" + f + "': index past the end of the palette (" +
                              std::to_string(list.size()) + " entries)",
                          f);
    }
  }
  return std::nullopt;
}

std::optional<Problem> patchBlocks(const json& blocks, json& doc) {
  if (!blocks.is_object()) return invalidField("field 'blocks': expected an object", "blocks");
  for (auto it = blocks.begin(); it != blocks.end(); ++it) {
    if (it.value().is_null()) {
      doc["blocks"].erase(it.key());
    } else {
      doc["blocks"][it.key()] = it.value();
    }
  }
  return std::nullopt;
}

std::optional<Problem> readEdit(const json& e, const std::string& path, const json& doc,
                                const Scene& s, std::array<int, 3>& at, json& block, int& rot) {
  if (!e.is_object()) return invalidField("field '" + path + "': expected an object", path);
  for (auto it = e.begin(); it != e.end(); ++it) {
    if (it.key() != "at" && it.key() != "block" && it.key() != "rot") {
      return invalidField("field '" + path + "." + it.key() + "': unknown key",
                          path + "." + it.key());
    }
  }
  const json& a = e.contains("at") ? e["at"] : json();
  if (!a.is_array() || a.size() != 3)
    return invalidField("field '" + path + ".at': expected 3 integers", path + ".at");
  for (int i = 0; i < 3; ++i) {
    const std::string f = path + ".at[" + std::to_string(i) + "]";
    if (!a[i].is_number_integer()) return invalidField("field '" + f + "': expected an integer", f);
    long long v = a[i].get<long long>();
    if (v < 0 || v >= s.size[i]) {
      return invalidField("field '" + f + "': value " + std::to_string(v) + " outside the grid", f);
    }
    at[i] = int(v);
  }
  if (!e.contains("block"))
    return invalidField("field '" + path + ".block': required (null empties the slot)",
                        path + ".block");
  block = e["block"];
  if (!block.is_null() &&
      !(block.is_string() && doc["blocks"].contains(block.get<std::string>()))) {
    return invalidField("field '" + path + ".block': not a block name of the scene",
                        path + ".block");
  }
  rot = 0;
  if (e.contains("rot")) {
    if (!e["rot"].is_number_integer() || e["rot"].get<long long>() < 0 ||
        e["rot"].get<long long>() > 23) {
      return invalidField("field '" + path + ".rot': expected an integer in 0..23", path + ".rot");
    }
    rot = e["rot"].get<int>();
  }
  return std::nullopt;
}

std::optional<Problem> patchEdits(const json& edits, json& doc, const Scene& s) {
  if (!edits.is_array()) return invalidField("field 'edits': expected an array", "edits");
  for (size_t n = 0; n < edits.size(); ++n) {
    std::array<int, 3> at{};
    json block;
    int rot = 0;
    if (auto p = readEdit(edits[n], "edits[" + std::to_string(n) + "]", doc, s, at, block, rot))
      return p;
    json& placements = doc["placements"];
    for (size_t i = placements.size(); i-- > 0;) {
      if (placements[i]["at"] == json(at)) placements.erase(i);
    }
    if (!block.is_null()) placements.push_back({{"at", at}, {"block", block}, {"rot", rot}});
  }
  return std::nullopt;
}

// sun / sky / bake objects merge into the current value; null removes the sun.
void patchValue(const json& patch, const char* key, json& doc) {
  if (!patch.contains(key)) return;
  const json& v = patch[key];
  if (v.is_null() && std::string(key) == "sun") {
    doc.erase("sun");
  } else if (v.is_object() && doc.contains(key) && doc[key].is_object()) {
    doc[key].update(v);
  } else {
    doc[key] = v;
  }
}

}  // namespace

std::variant<Scene, Problem> applyScenePatch(const Scene& current, const json& patch) {
  if (auto p = checkPatchKeys(patch)) return *p;
  json doc = json::parse(sceneToJson(current));
  if (patch.contains("palette")) {
    if (auto p = patchPalette(patch["palette"], doc)) return *p;
  }
  if (patch.contains("blocks")) {
    if (auto p = patchBlocks(patch["blocks"], doc)) return *p;
  }
  if (patch.contains("edits")) {
    if (auto p = patchEdits(patch["edits"], doc, current)) return *p;
  }
  for (const char* key : {"sun", "sky", "emission_scale", "ambient", "bake"})
    patchValue(patch, key, doc);
  Expected<Scene> scene = parseSceneJson(doc.dump());
  if (!scene) return sceneProblem(scene.error());
  return std::move(*scene);
}

}  // namespace rdm::server
