#include "rdm/scene/scene_patch.h"

#include <map>

namespace rdm {
namespace {

using nlohmann::json;

constexpr const char* kPatchKeys[] = {"base_version", "blocks",         "palette", "edits", "sun",
                                      "sky",          "emission_scale", "ambient", "bake",  "size"};

Status checkPatchKeys(const json& patch) {
  if (!patch.is_object()) return Status::invalid({}, "the PATCH body must be a JSON object");
  for (auto it = patch.begin(); it != patch.end(); ++it) {
    bool known = false;
    for (const char* k : kPatchKeys) known = known || it.key() == k;
    if (!known) return Status::invalidField(it.key(), "unknown key");
  }
  return {};
}

// "palette": {"<index>": entry}; an index replaces an entry or appends right after the end.
Status patchPalette(const json& palette, json& doc) {
  if (!palette.is_object())
    return Status::invalidField("palette", "expected an object keyed by index");
  std::map<int, const json*> by_index;
  for (auto it = palette.begin(); it != palette.end(); ++it) {
    const std::string& key = it.key();
    char* end = nullptr;
    long index = std::strtol(key.c_str(), &end, 10);
    if (key.empty() || *end || index < 1 || index > 255) {
      return Status::invalidField("palette." + key, "index must be an integer in 1..255");
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
      return Status::invalidField(
          f, "index past the end of the palette (" + std::to_string(list.size()) + " entries)");
    }
  }
  return {};
}

Status patchBlocks(const json& blocks, json& doc) {
  if (!blocks.is_object()) return Status::invalidField("blocks", "expected an object");
  for (auto it = blocks.begin(); it != blocks.end(); ++it) {
    if (it.value().is_null()) {
      doc["blocks"].erase(it.key());
    } else {
      doc["blocks"][it.key()] = it.value();
    }
  }
  return {};
}

Status readEdit(const json& e, const std::string& path, const json& doc,
                const std::array<int, 3>& size, std::array<int, 3>& at, json& block, int& rot) {
  if (!e.is_object()) return Status::invalidField(path, "expected an object");
  for (auto it = e.begin(); it != e.end(); ++it) {
    if (it.key() != "at" && it.key() != "block" && it.key() != "rot") {
      return Status::invalidField(path + "." + it.key(), "unknown key");
    }
  }
  const json& a = e.contains("at") ? e["at"] : json();
  if (!a.is_array() || a.size() != 3)
    return Status::invalidField(path + ".at", "expected 3 integers");
  for (int i = 0; i < 3; ++i) {
    const std::string f = path + ".at[" + std::to_string(i) + "]";
    if (!a[i].is_number_integer()) return Status::invalidField(f, "expected an integer");
    long long v = a[i].get<long long>();
    if (v < 0 || v >= size[i]) {
      return Status::invalidField(f, "value " + std::to_string(v) + " outside the grid");
    }
    at[i] = int(v);
  }
  if (!e.contains("block"))
    return Status::invalidField(path + ".block", "required (null empties the slot)");
  block = e["block"];
  if (!block.is_null() &&
      !(block.is_string() && doc["blocks"].contains(block.get<std::string>()))) {
    return Status::invalidField(path + ".block", "not a block name of the scene");
  }
  rot = 0;
  if (e.contains("rot")) {
    if (!e["rot"].is_number_integer() || e["rot"].get<long long>() < 0 ||
        e["rot"].get<long long>() > 23) {
      return Status::invalidField(path + ".rot", "expected an integer in 0..23");
    }
    rot = e["rot"].get<int>();
  }
  return {};
}

Status patchEdits(const json& edits, json& doc, const std::array<int, 3>& size) {
  if (!edits.is_array()) return Status::invalidField("edits", "expected an array");
  for (size_t n = 0; n < edits.size(); ++n) {
    std::array<int, 3> at{};
    json block;
    int rot = 0;
    const std::string path = "edits[" + std::to_string(n) + "]";
    if (Status st = readEdit(edits[n], path, doc, size, at, block, rot); !st.ok()) return st;
    json& placements = doc["placements"];
    for (size_t i = placements.size(); i-- > 0;) {
      if (placements[i]["at"] == json(at)) placements.erase(i);
    }
    if (!block.is_null()) placements.push_back({{"at", at}, {"block", block}, {"rot", rot}});
  }
  return {};
}

// "size": [x, y, z]; the loader checks placements against it and the limits.
Status patchSize(const json& value, std::array<int, 3>& size) {
  if (!value.is_array() || value.size() != 3)
    return Status::invalidField("size", "expected 3 integers");
  for (int i = 0; i < 3; ++i) {
    const std::string f = "size[" + std::to_string(i) + "]";
    if (!value[size_t(i)].is_number_integer() || value[size_t(i)].get<long long>() < 1 ||
        value[size_t(i)].get<long long>() > 4096)
      return Status::invalidField(f, "expected an integer in 1..4096");
    size[size_t(i)] = value[size_t(i)].get<int>();
  }
  return {};
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

Expected<Scene> applyScenePatch(const Scene& current, const json& patch) {
  if (Status st = checkPatchKeys(patch); !st.ok()) return st;
  json doc = json::parse(sceneToJson(current));
  if (patch.contains("palette")) {
    if (Status st = patchPalette(patch["palette"], doc); !st.ok()) return st;
  }
  if (patch.contains("blocks")) {
    if (Status st = patchBlocks(patch["blocks"], doc); !st.ok()) return st;
  }
  std::array<int, 3> size = current.size;
  if (patch.contains("size")) {
    if (Status st = patchSize(patch["size"], size); !st.ok()) return st;
    doc["size"] = size;
  }
  if (patch.contains("edits")) {
    if (Status st = patchEdits(patch["edits"], doc, size); !st.ok()) return st;
  }
  for (const char* key : {"sun", "sky", "emission_scale", "ambient", "bake"})
    patchValue(patch, key, doc);
  Expected<Scene> scene = parseSceneJson(doc.dump());
  if (!scene) return scene.status();
  return std::move(*scene);
}

namespace {

std::map<std::array<int, 3>, Placement> placementsBySlot(const Scene& scene) {
  std::map<std::array<int, 3>, Placement> out;
  for (const Placement& p : scene.placements) out[p.at] = p;
  return out;
}

json placementEdits(const Scene& from, const Scene& to) {
  json edits = json::array();
  const auto before = placementsBySlot(from), after = placementsBySlot(to);
  for (const auto& [at, p] : after) {
    const auto it = before.find(at);
    if (it == before.end() || !(it->second == p))
      edits.push_back({{"at", at}, {"block", p.block}, {"rot", p.rot}});
  }
  for (const auto& [at, p] : before) {
    if (!after.count(at)) edits.push_back({{"at", at}, {"block", nullptr}});
  }
  return edits;
}

}  // namespace

json makeScenePatch(const Scene& from, const Scene& to, long long base_version) {
  const json from_json = json::parse(sceneToJson(from)), to_json = json::parse(sceneToJson(to));
  json body = {{"base_version", base_version}};
  json blocks = json::object(), palette = json::object();
  for (const auto& [name, block] : to.blocks) {
    const auto it = from.blocks.find(name);
    if (it == from.blocks.end() || it->second != block) blocks[name] = to_json["blocks"][name];
  }
  for (size_t i = 0; i < to.palette.size(); ++i) {
    if (i >= from.palette.size() || from.palette[i] != to.palette[i])
      palette[std::to_string(i + 1)] = to_json["palette"][i];
  }
  const json edits = placementEdits(from, to);
  if (!blocks.empty()) body["blocks"] = blocks;
  if (!palette.empty()) body["palette"] = palette;
  if (!edits.empty()) body["edits"] = edits;
  for (const char* key : {"size", "sky", "emission_scale", "ambient", "bake"}) {
    if (to_json.value(key, json()) != from_json.value(key, json())) body[key] = to_json[key];
  }
  if (to_json.value("sun", json()) != from_json.value("sun", json()))
    body["sun"] = to_json.value("sun", json());
  return body;
}

bool scenePatchIsEmpty(const json& patch) {
  for (auto it = patch.begin(); it != patch.end(); ++it) {
    if (it.key() != "base_version") return false;
  }
  return true;
}

}  // namespace rdm
