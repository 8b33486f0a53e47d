// Scene JSON v1 (docs/spec.md section 2). Field errors are thrown internally as FieldError and
// turned into a Status at the public boundary.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "rdm/base/base64.h"
#include "rdm/base/check.h"
#include "rdm/base/file_util.h"
#include "rdm/base/json_parse.h"
#include "rdm/scene/bake_settings_json.h"
#include "rdm/scene/scene.h"
#include "scene_sax.h"

namespace rdm {
namespace {

using nlohmann::json;

struct FieldError {
  std::string field;
  std::string message;
};

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw FieldError{path, "field '" + path + "': " + what};
}

void checkKeys(const json& j, const std::string& path, std::initializer_list<const char*> allowed) {
  if (!j.is_object()) fail(path, "expected an object");
  for (auto it = j.begin(); it != j.end(); ++it) {
    bool known = false;
    for (const char* key : allowed) known = known || it.key() == key;
    if (!known) fail(path.empty() ? it.key() : path + "." + it.key(), "unknown key");
  }
}

std::string join(const std::string& path, const std::string& key) {
  return path.empty() ? key : path + "." + key;
}

double readNumber(const json& j, const std::string& path, double lo, double hi) {
  if (!j.is_number()) fail(path, "expected a number");
  double v = j.get<double>();
  if (!std::isfinite(v) || v < lo || v > hi) {
    std::ostringstream os;
    os << "value " << v << " outside [" << lo << ", " << hi << "]";
    fail(path, os.str());
  }
  return v;
}

int64_t readInt(const json& j, const std::string& path, int64_t lo, int64_t hi) {
  if (!j.is_number_integer()) fail(path, "expected an integer");
  int64_t v = j.is_number_unsigned() ? int64_t(std::min<uint64_t>(j.get<uint64_t>(), INT64_MAX))
                                     : j.get<int64_t>();
  if (v < lo || v > hi) {
    fail(path, "value " + std::to_string(v) + " outside [" + std::to_string(lo) + ", " +
                   std::to_string(hi) + "]");
  }
  return v;
}

glm::dvec3 readVec3(const json& j, const std::string& path, double lo, double hi) {
  if (!j.is_array() || j.size() != 3) fail(path, "expected an array of 3 numbers");
  glm::dvec3 v;
  for (int i = 0; i < 3; ++i) v[i] = readNumber(j[i], path + "[" + std::to_string(i) + "]", lo, hi);
  return v;
}

std::array<int, 3> readInt3(const json& j, const std::string& path, int lo, int hi) {
  if (!j.is_array() || j.size() != 3) fail(path, "expected an array of 3 integers");
  std::array<int, 3> v{};
  for (int i = 0; i < 3; ++i)
    v[i] = int(readInt(j[i], path + "[" + std::to_string(i) + "]", lo, hi));
  return v;
}

PaletteEntry readPaletteEntry(const json& j, const std::string& path) {
  checkKeys(j, path, {"color", "roughness", "metallic", "emission", "transmission", "ior"});
  PaletteEntry e;
  if (!j.contains("color")) fail(join(path, "color"), "required");
  e.color = readInt3(j["color"], join(path, "color"), 0, 255);
  if (j.contains("roughness"))
    e.roughness = int(readInt(j["roughness"], join(path, "roughness"), 0, 7));
  if (j.contains("metallic"))
    e.metallic = int(readInt(j["metallic"], join(path, "metallic"), 0, 3));
  if (j.contains("emission"))
    e.emission = int(readInt(j["emission"], join(path, "emission"), 0, 3));
  if (j.contains("transmission"))
    e.transmission = readNumber(j["transmission"], join(path, "transmission"), 0, 1);
  if (j.contains("ior")) e.ior = readNumber(j["ior"], join(path, "ior"), 1, 3);
  return e;
}

Block readBlock(const json& j, const std::string& path, size_t palette_size) {
  checkKeys(j, path, {"fill", "voxels"});
  if (j.contains("fill") == j.contains("voxels"))
    fail(path, "exactly one of 'fill' or 'voxels' required");
  Block block;
  if (j.contains("fill")) {
    int fill = int(readInt(j["fill"], join(path, "fill"), 0, 255));
    if (size_t(fill) > palette_size) {
      fail(join(path, "fill"), "palette index " + std::to_string(fill) + " past the palette (" +
                                   std::to_string(palette_size) + " entries)");
    }
    block.voxels.assign(4096, uint8_t(fill));
    return block;
  }
  const std::string vpath = join(path, "voxels");
  if (!j["voxels"].is_string()) fail(vpath, "expected a base64 string");
  auto bytes = base64Decode(j["voxels"].get<std::string>());
  if (!bytes) fail(vpath, bytes.error());
  if (bytes->size() != 4096) {
    fail(vpath, "decoded payload is " + std::to_string(bytes->size()) + " bytes, expected 4096");
  }
  for (size_t i = 0; i < 4096; ++i) {
    if ((*bytes)[i] > palette_size) {
      fail(vpath, "voxel " + std::to_string(i) + " uses palette index " +
                      std::to_string((*bytes)[i]) + " past the palette (" +
                      std::to_string(palette_size) + " entries)");
    }
  }
  block.voxels = std::move(*bytes);
  return block;
}

Placement readPlacement(const json& j, const std::string& path, const Scene& scene) {
  checkKeys(j, path, {"at", "block", "rot"});
  Placement p;
  if (!j.contains("at")) fail(join(path, "at"), "required");
  for (int a = 0; a < 3; ++a) {
    const std::string apath = join(path, "at") + "[" + std::to_string(a) + "]";
    if (!j["at"].is_array() || j["at"].size() != 3)
      fail(join(path, "at"), "expected an array of 3 integers");
    int64_t v = readInt(j["at"][a], apath, INT32_MIN, INT32_MAX);
    if (v < 0 || v >= scene.size[a]) {
      fail(apath, "placement " + std::to_string(v) + " outside the grid [0, " +
                      std::to_string(scene.size[a]) + ")");
    }
    p.at[a] = int(v);
  }
  if (!j.contains("block") || !j["block"].is_string())
    fail(join(path, "block"), "expected a block name");
  p.block = j["block"].get<std::string>();
  if (!scene.blocks.count(p.block))
    fail(join(path, "block"), "unknown block name '" + p.block + "'");
  if (j.contains("rot")) p.rot = int(readInt(j["rot"], join(path, "rot"), 0, 23));
  return p;
}

Sun readSun(const json& j, const std::string& path) {
  checkKeys(j, path, {"direction", "irradiance", "angular_radius_deg"});
  Sun sun;
  if (!j.contains("direction")) fail(join(path, "direction"), "required");
  sun.direction = readVec3(j["direction"], join(path, "direction"), -1e30, 1e30);
  if (!directionUsable(sun.direction)) fail(join(path, "direction"), "must be non-zero");
  if (j.contains("irradiance"))
    sun.irradiance = readVec3(j["irradiance"], join(path, "irradiance"), 0, 1e5);
  if (j.contains("angular_radius_deg")) {
    sun.angular_radius_deg =
        readNumber(j["angular_radius_deg"], join(path, "angular_radius_deg"), 0.01, 10);
  }
  return sun;
}

Sky readSky(const json& j, const std::string& path) {
  checkKeys(j, path, {"zenith", "horizon", "ground"});
  Sky sky;
  if (j.contains("zenith")) sky.zenith = readVec3(j["zenith"], join(path, "zenith"), 0, 1e5);
  if (j.contains("horizon")) sky.horizon = readVec3(j["horizon"], join(path, "horizon"), 0, 1e5);
  if (j.contains("ground")) sky.ground = readVec3(j["ground"], join(path, "ground"), 0, 1e5);
  return sky;
}

// The scene's "bake": the settings through their codec, and face_light_spp beside them.
BakeSettings readBake(const json& j, const std::string& path, int& face_light_spp) {
  const auto raise = [](const Status& s) { throw FieldError{s.field(), s.message()}; };
  if (Status s = checkBakeSettingsKeys(j, path, {"face_light_spp"}); !s) raise(s);
  if (j.contains("face_light_spp")) {
    auto spp = readFaceLightSpp(j["face_light_spp"], join(path, "face_light_spp"));
    if (!spp) raise(spp.status());
    face_light_spp = *spp;
  }
  auto settings =
      readBakeSettings(j, {path, BakeSettings{}, BakeSettingsForm::kInput, {"face_light_spp"}});
  if (!settings) raise(settings.status());
  return *settings;
}

Camera readCamera(const json& j, const std::string& path) {
  checkKeys(j, path, {"position", "target", "fov_deg", "name"});
  Camera c;
  if (j.contains("name")) {
    if (!j["name"].is_string()) fail(join(path, "name"), "expected a string");
    c.name = j["name"].get<std::string>();
  }
  if (!j.contains("position")) fail(join(path, "position"), "required");
  if (!j.contains("target")) fail(join(path, "target"), "required");
  c.position = readVec3(j["position"], join(path, "position"), -1e6, 1e6);
  c.target = readVec3(j["target"], join(path, "target"), -1e6, 1e6);
  if (j.contains("fov_deg")) {
    c.fov_deg = readNumber(j["fov_deg"], join(path, "fov_deg"), 0, 180);
    if (c.fov_deg <= 0 || c.fov_deg >= 180) fail(join(path, "fov_deg"), "must be in (0, 180)");
  }
  if (!cameraUsable(c)) fail(path, "target - position is parallel to Y (or zero)");
  return c;
}

template <class T, class F>
std::vector<T> readArray(const json& j, const std::string& path, F read_one) {
  if (!j.is_array()) fail(path, "expected an array");
  std::vector<T> out;
  for (size_t i = 0; i < j.size(); ++i)
    out.push_back(read_one(j[i], path + "[" + std::to_string(i) + "]"));
  return out;
}

// Placements read by SceneSax: the grid and block checks of readPlacement, same messages.
std::vector<Placement> readCompactPlacements(const PlacementList& list, const Scene& scene) {
  std::vector<bool> known(list.names.size());
  for (size_t n = 0; n < list.names.size(); ++n) known[n] = scene.blocks.count(list.names[n]) > 0;
  std::vector<Placement> out;
  out.reserve(list.items.size());
  for (size_t i = 0; i < list.items.size(); ++i) {
    if ((long long)i == list.error_index) throw FieldError{list.error_field, list.error};
    const CompactPlacement& c = list.items[i];
    Placement p;
    for (int a = 0; a < 3; ++a) {
      if (c.at[a] < 0 || c.at[a] >= scene.size[a]) {
        fail("placements[" + std::to_string(i) + "].at[" + std::to_string(a) + "]",
             "placement " + std::to_string(c.at[a]) + " outside the grid [0, " +
                 std::to_string(scene.size[a]) + ")");
      }
      p.at[a] = c.at[a];
    }
    p.block = list.names[c.block];
    if (!known[c.block])
      fail("placements[" + std::to_string(i) + "].block", "unknown block name '" + p.block + "'");
    p.rot = c.rot;
    out.push_back(std::move(p));
  }
  return out;
}

Scene readScene(const json& j, const PlacementList* list) {
  checkKeys(j, "",
            {"format", "version", "size", "palette", "blocks", "placements", "sun", "sky",
             "emission_scale", "ambient", "bake", "cameras"});
  if (!j.contains("format") || j["format"] != "rdm-scene") fail("format", "must be \"rdm-scene\"");
  if (!j.contains("version") || !j["version"].is_number_integer() || j["version"] != 1) {
    fail("version", "must be 1");
  }
  Scene s;
  if (!j.contains("size")) fail("size", "required");
  s.size = readInt3(j["size"], "size", 1, 256);
  if (j.contains("palette")) {
    if (j["palette"].is_array() && j["palette"].size() > 255)
      fail("palette", "at most 255 entries");
    s.palette = readArray<PaletteEntry>(j["palette"], "palette", readPaletteEntry);
  }
  if (j.contains("blocks")) {
    if (!j["blocks"].is_object()) fail("blocks", "expected an object");
    for (auto it = j["blocks"].begin(); it != j["blocks"].end(); ++it) {
      if (it.key().empty()) fail("blocks", "empty block name");
      s.blocks[it.key()] = readBlock(it.value(), "blocks." + it.key(), s.palette.size());
    }
  }
  if (list && list->present) {
    s.placements = readCompactPlacements(*list, s);
  } else if (j.contains("placements")) {
    s.placements = readArray<Placement>(
        j["placements"], "placements",
        [&](const json& e, const std::string& p) { return readPlacement(e, p, s); });
  }
  if (j.contains("sun") && !j["sun"].is_null()) s.sun = readSun(j["sun"], "sun");
  if (j.contains("sky")) s.sky = readSky(j["sky"], "sky");
  if (j.contains("emission_scale"))
    s.emission_scale = readNumber(j["emission_scale"], "emission_scale", 0, 1e5);
  if (j.contains("ambient")) s.ambient = readVec3(j["ambient"], "ambient", 0, 1e5);
  if (j.contains("bake")) s.bake = readBake(j["bake"], "bake", s.face_light_spp);
  if (j.contains("cameras")) s.cameras = readArray<Camera>(j["cameras"], "cameras", readCamera);
  return s;
}

}  // namespace

Expected<Scene> parseSceneJson(const std::string& text) {
  json j;
  PlacementList placements;
  {
    SceneSax sax(j, jsonBudget(text.size()), placements);
    if (!json::sax_parse(text, &sax)) {
      if (!sax.error().ok()) return sax.error();
      return Status::error(StatusCode::kMalformed, "invalid JSON");
    }
  }
  try {
    Scene scene = readScene(j, &placements);
    Status status = validateScene(scene);
    if (!status) return status;
    return scene;
  } catch (const FieldError& e) {
    return Status::invalid(e.field, e.message);
  } catch (const std::exception&) {  // never quotes the library's text (it may echo input)
    return Status::error(StatusCode::kInvalidInput,
                         "invalid scene: the document could not be read");
  }
}

Expected<Scene> loadSceneFile(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    return Status::error(StatusCode::kInvalidInput, path + ": is a directory, not a scene file");
  auto text = readFileToString(path);
  if (!text) return text.status();
  if (text->empty())
    return Status::error(
        StatusCode::kInvalidInput,
        path + ": scene file is empty (a scene is a JSON object, docs/spec.md section 2)");
  auto scene = parseSceneJson(*text);
  if (!scene) {
    return Status::error(scene.status().code(), path + ": " + scene.error(),
                         scene.status().field());
  }
  return scene;
}

}  // namespace rdm
