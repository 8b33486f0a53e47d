// The scene model of docs/spec.md section 2: a grid of slots holding oriented blocks of 16^3
// palette-indexed voxels, plus lights, bake settings and cameras.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "rdm/base/status.h"

namespace rdm {

struct PaletteEntry {
  std::array<int, 3> color{0, 0, 0};  // sRGB 0..255
  int roughness = 7;                  // 0..7
  int metallic = 0;                   // 0..3
  int emission = 0;                   // 0..3
  // Glass (docs/spec.md sections 2 and 5): the fraction of hits that meet a smooth
  // dielectric of index `ior` tinted by `color` instead of the opaque surface above. 0: opaque.
  double transmission = 0.0;  // 0..1
  double ior = 1.5;           // 1..3
  bool operator==(const PaletteEntry&) const = default;
};

// 4096 palette indices (0 = empty), voxel index x + 16 y + 256 z, block-local.
struct Block {
  std::vector<uint8_t> voxels = std::vector<uint8_t>(4096, 0);
  bool operator==(const Block&) const = default;
};

struct Placement {
  std::array<int, 3> at{0, 0, 0};
  std::string block;
  int rot = 0;  // 0..23, docs/spec.md section 1
  bool operator==(const Placement&) const = default;
};

struct Sun {
  glm::dvec3 direction{0.0, 1.0, 0.0};  // towards the sun, not necessarily normalised
  glm::dvec3 irradiance{0.0};           // W/m^2-like units; white Lambert reflects E/pi
  double angular_radius_deg = 0.27;
  bool operator==(const Sun&) const = default;
};

struct Sky {
  glm::dvec3 zenith{0.0}, horizon{0.0}, ground{0.0};
  bool operator==(const Sky&) const = default;
};

// How a rough or diffuse level is estimated (docs/spec.md section 3.1): kNaive path traces every
// level on its own; kPrefiltered traces one radiance map per face and derives the levels from it.
enum class Estimator { kNaive, kPrefiltered };
const char* estimatorName(Estimator e);
// Parses "naive" or "prefiltered"; anything else is refused with the name and the choices.
Expected<Estimator> parseEstimator(const std::string& name);

struct BakeSettings {
  int spp = 256;
  int max_bounces = 4;
  uint32_t seed = 1;
  int max_hemisphere = 256;
  Estimator estimator = Estimator::kPrefiltered;
  bool operator==(const BakeSettings&) const = default;
};

struct Camera {
  glm::dvec3 position{0.0}, target{0.0, 0.0, 1.0};
  double fov_deg = 50.0;
  // Optional; when set, unique within the scene, 1..64 characters of [A-Za-z0-9_-], and not
  // all digits (so `--camera 2` always means the index).
  std::string name;
  bool operator==(const Camera&) const = default;
};

struct Scene {
  std::array<int, 3> size{1, 1, 1};
  std::vector<PaletteEntry> palette;  // palette[0] is index 1
  std::map<std::string, Block> blocks;
  std::vector<Placement> placements;
  std::optional<Sun> sun;
  Sky sky;
  double emission_scale = 1.0;
  glm::dvec3 ambient{0.0};
  BakeSettings bake;
  // bake.face_light_spp: samples per exposed voxel face of the face light that `rdm bake` and
  // the daemon bake by default (docs/spec.md sections 2 and 3.2); 0: none. Not a BakeSettings
  // field: it changes no RDM, so changing it re-bakes none.
  int face_light_spp = 0;
  std::vector<Camera> cameras;
  bool operator==(const Scene&) const = default;
};

// A direction is usable when it is finite and non-zero after scaling by its largest
// component (so tiny but valid directions normalise exactly).
bool directionUsable(const glm::dvec3& d);
glm::dvec3 normalizeDirection(const glm::dvec3& d);
// The docs/spec.md section 4 camera basis exists: forward is finite and not (nearly) parallel to Y.
bool cameraUsable(const Camera& camera);
// `--camera`'s argument: a 0-based index or a camera name. The error lists the cameras.
Expected<size_t> findCamera(const Scene& scene, const std::string& index_or_name);

// Checks every docs/spec.md section 2 range and reference; the message names the field.
Status validateScene(const Scene& scene);

// JSON v1 (docs/spec.md section 2). Errors name the field path (e.g. `placements[3].at[1]`) or the
// byte offset of malformed JSON / base64.
Expected<Scene> parseSceneJson(const std::string& text);
Expected<Scene> loadSceneFile(const std::string& path);
// The document, ending in a newline: one field a line, one placement a line.
std::string sceneToJson(const Scene& scene);
Status saveSceneFile(const std::string& path, const Scene& scene);
// Whether a voxel of a placed block is glass (PaletteEntry::transmission > 0).
bool usesGlass(const Scene& scene);

// Built-in scenes (docs/spec.md section 7): "island", "chess", and small test scenes.
std::vector<std::string> builtinSceneNames();
Expected<Scene> builtinScene(const std::string& name);
// Loads `name_or_path` as a built-in name when it is one, else as a JSON file.
// A built-in scene by name, else a scene file; neither names both choices (the built-in
// list and the OS's reason) and suggests a close built-in name.
Expected<Scene> loadSceneByNameOrPath(const std::string& name_or_path);
std::string builtinSceneList();  // "chess, island, ..."

}  // namespace rdm
