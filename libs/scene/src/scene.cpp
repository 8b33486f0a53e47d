#include "rdm/scene/scene.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <set>

#include <nlohmann/json.hpp>

#include "rdm/scene/bake_settings_json.h"

namespace rdm {
namespace {

std::string at(const std::string& field, size_t i) {
  return field + "[" + std::to_string(i) + "]";
}

bool inRange(const glm::dvec3& v, double lo, double hi) {
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(v[i]) || v[i] < lo || v[i] > hi) return false;
  }
  return true;
}

Status validatePalette(const Scene& s) {
  if (s.palette.size() > 255) return Status::invalidField("palette", "at most 255 entries");
  for (size_t i = 0; i < s.palette.size(); ++i) {
    const PaletteEntry& e = s.palette[i];
    for (int c : e.color) {
      if (c < 0 || c > 255)
        return Status::invalidField(at("palette", i) + ".color", "outside 0..255");
    }
    if (e.roughness < 0 || e.roughness > 7 || e.metallic < 0 || e.metallic > 3 || e.emission < 0 ||
        e.emission > 3) {
      return Status::invalidField(at("palette", i), "roughness/metallic/emission out of range");
    }
    if (!(e.transmission >= 0.0 && e.transmission <= 1.0))
      return Status::invalidField(at("palette", i) + ".transmission", "outside 0..1");
    if (!(e.ior >= 1.0 && e.ior <= 3.0))
      return Status::invalidField(at("palette", i) + ".ior", "outside 1..3");
  }
  return {};
}

Status validateBlocks(const Scene& s) {
  for (const auto& [name, block] : s.blocks) {
    if (block.voxels.size() != 4096)
      return Status::invalidField("blocks." + name, "expected 4096 voxels");
    for (size_t v = 0; v < 4096; ++v) {
      if (block.voxels[v] > s.palette.size()) {
        return Status::invalidField("blocks." + name, "voxel " + std::to_string(v) +
                                                          " uses palette index past the palette");
      }
    }
  }
  return {};
}

Status validatePlacements(const Scene& s) {
  // One bit per grid slot (at most 256^3 bits = 2 MiB), not a set node of ~64 bytes a placement.
  std::vector<bool> used(size_t(std::max(0, s.size[0])) * size_t(std::max(0, s.size[1])) *
                         size_t(std::max(0, s.size[2])));
  for (size_t i = 0; i < s.placements.size(); ++i) {
    const Placement& p = s.placements[i];
    for (int a = 0; a < 3; ++a) {
      if (p.at[a] < 0 || p.at[a] >= s.size[a]) {
        return Status::invalidField(at("placements", i) + ".at[" + std::to_string(a) + "]",
                                    "placement " + std::to_string(p.at[a]) +
                                        " outside the grid [0, " + std::to_string(s.size[a]) + ")");
      }
    }
    if (!s.blocks.count(p.block)) {
      return Status::invalidField(at("placements", i) + ".block",
                                  "unknown block name '" + p.block + "'");
    }
    if (p.rot < 0 || p.rot > 23)
      return Status::invalidField(at("placements", i) + ".rot", "outside 0..23");
    const size_t slot =
        (size_t(p.at[2]) * size_t(s.size[1]) + size_t(p.at[1])) * size_t(s.size[0]) +
        size_t(p.at[0]);
    if (used[slot]) {
      return Status::invalidField(at("placements", i) + ".at", "slot already holds a block");
    }
    used[slot] = true;
  }
  return {};
}

Status validateLights(const Scene& s) {
  if (s.sun) {
    if (!inRange(s.sun->direction, -1e30, 1e30) || !directionUsable(s.sun->direction)) {
      return Status::invalidField("sun.direction", "must be finite and non-zero");
    }
    if (!inRange(s.sun->irradiance, 0, 1e5))
      return Status::invalidField("sun.irradiance", "outside 0..1e5");
    if (!(s.sun->angular_radius_deg >= 0.01 && s.sun->angular_radius_deg <= 10)) {
      return Status::invalidField("sun.angular_radius_deg", "outside [0.01, 10]");
    }
  }
  if (!inRange(s.sky.zenith, 0, 1e5) || !inRange(s.sky.horizon, 0, 1e5) ||
      !inRange(s.sky.ground, 0, 1e5)) {
    return Status::invalidField("sky", "components outside 0..1e5");
  }
  if (!(s.emission_scale >= 0 && s.emission_scale <= 1e5)) {
    return Status::invalidField("emission_scale", "outside 0..1e5");
  }
  if (!inRange(s.ambient, 0, 1e5)) return Status::invalidField("ambient", "outside 0..1e5");
  return {};
}

bool cameraNameValid(const std::string& name) {
  if (name.empty() || name.size() > 64) return false;
  const auto allowed = [](char c) {
    return std::isalnum((unsigned char)c) || c == '_' || c == '-';
  };
  const auto digit = [](char c) { return std::isdigit((unsigned char)c) != 0; };
  return std::all_of(name.begin(), name.end(), allowed) &&
         !std::all_of(name.begin(), name.end(), digit);
}

Status validateCameraNames(const Scene& s) {
  std::set<std::string> seen;
  for (size_t i = 0; i < s.cameras.size(); ++i) {
    const std::string& name = s.cameras[i].name;
    if (name.empty()) continue;
    if (!cameraNameValid(name)) {
      return Status::invalidField(at("cameras", i) + ".name",
                                  "1..64 of [A-Za-z0-9_-], not all digits");
    }
    if (!seen.insert(name).second)
      return Status::invalidField(at("cameras", i) + ".name", "'" + name + "' used twice");
  }
  return {};
}

Status validateSettings(const Scene& s) {
  if (Status r = validateCameraNames(s); !r) return r;
  if (Status r = validateBakeSettings(s.bake, "bake"); !r) return r;
  if (Status r = checkFaceLightSpp(s.face_light_spp); !r) return r;
  for (size_t i = 0; i < s.cameras.size(); ++i) {
    const Camera& c = s.cameras[i];
    if (!inRange(c.position, -1e6, 1e6) || !inRange(c.target, -1e6, 1e6) || !cameraUsable(c)) {
      return Status::invalidField(at("cameras", i),
                                  "target - position must be finite and not parallel to Y");
    }
    if (!(c.fov_deg > 0 && c.fov_deg < 180))
      return Status::invalidField(at("cameras", i) + ".fov_deg", "must be in (0, 180)");
  }
  return {};
}

}  // namespace

bool usesGlass(const Scene& scene) {
  std::vector<bool> glass(scene.palette.size() + 1, false);
  bool any = false;
  for (size_t i = 0; i < scene.palette.size(); ++i)
    any = any || (glass[i + 1] = scene.palette[i].transmission > 0.0);
  if (!any) return false;
  std::set<std::string> placed;
  for (const Placement& p : scene.placements) placed.insert(p.block);
  for (const std::string& name : placed) {
    const auto it = scene.blocks.find(name);
    if (it == scene.blocks.end()) continue;
    for (uint8_t v : it->second.voxels)
      if (v < glass.size() && glass[v]) return true;
  }
  return false;
}

bool directionUsable(const glm::dvec3& d) {
  double m = std::max({std::abs(d.x), std::abs(d.y), std::abs(d.z)});
  return std::isfinite(m) && m > 0.0;
}

glm::dvec3 normalizeDirection(const glm::dvec3& d) {
  double m = std::max({std::abs(d.x), std::abs(d.y), std::abs(d.z)});
  return glm::normalize(d / m);
}

bool cameraUsable(const Camera& c) {
  glm::dvec3 f = c.target - c.position;
  if (!directionUsable(f)) return false;
  f = normalizeDirection(f);
  return std::hypot(f.x, f.z) > 1e-6;
}

Expected<size_t> findCamera(const Scene& s, const std::string& index_or_name) {
  const bool is_index = !index_or_name.empty() &&
                        std::all_of(index_or_name.begin(), index_or_name.end(),
                                    [](char c) { return std::isdigit((unsigned char)c) != 0; });
  for (size_t i = 0; i < s.cameras.size(); ++i) {
    if (is_index ? index_or_name == std::to_string(i) : s.cameras[i].name == index_or_name)
      return i;
  }
  std::string known;
  for (size_t i = 0; i < s.cameras.size(); ++i) {
    known += (i ? ", " : "") + std::to_string(i);
    if (!s.cameras[i].name.empty()) known += " (" + s.cameras[i].name + ")";
  }
  return Status::invalidField("camera", "no camera '" + index_or_name + "'; the scene has " +
                                            (known.empty() ? std::string("none") : known));
}

Status validateScene(const Scene& s) {
  for (int a = 0; a < 3; ++a) {
    if (s.size[a] < 1 || s.size[a] > 256) {
      return Status::invalidField("size[" + std::to_string(a) + "]", "outside 1..256");
    }
  }
  for (Status st : {validatePalette(s), validateBlocks(s), validatePlacements(s), validateLights(s),
                    validateSettings(s)}) {
    if (!st) return st;
  }
  return {};
}

namespace {

size_t editDistance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] != b[j - 1])});
      diagonal = up;
    }
  }
  return row[b.size()];
}

std::string suggestion(const std::string& source) {
  for (const std::string& name : builtinSceneNames()) {
    if (editDistance(source, name) <= 2) return " Did you mean '" + name + "'?";
  }
  return {};
}

}  // namespace

std::string builtinSceneList() {
  std::string list;
  for (const std::string& name : builtinSceneNames()) list += (list.empty() ? "" : ", ") + name;
  return list;
}

Expected<Scene> loadSceneByNameOrPath(const std::string& source) {
  for (const std::string& name : builtinSceneNames()) {
    if (name == source) return builtinScene(name);
  }
  std::ifstream probe(source, std::ios::binary);
  if (!probe) {
    const std::string reason = std::strerror(errno);
    return Status::notFound("'" + source + "' is neither a built-in scene (" + builtinSceneList() +
                            ") nor a readable scene file (" + reason + ")." + suggestion(source));
  }
  return loadSceneFile(source);
}

}  // namespace rdm

namespace rdm {

const char* estimatorName(Estimator e) {
  return e == Estimator::kNaive ? "naive" : "prefiltered";
}

Expected<Estimator> parseEstimator(const std::string& name) {
  for (Estimator e : {Estimator::kNaive, Estimator::kPrefiltered}) {
    if (name == estimatorName(e)) return e;
  }
  // Quoted as JSON (escaped, invalid UTF-8 replaced): the name may come from a request.
  const std::string quoted =
      nlohmann::json(name).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  return Status::invalid("",
                         "unknown estimator " + quoted + "; expected \"naive\" or \"prefiltered\"");
}

}  // namespace rdm
