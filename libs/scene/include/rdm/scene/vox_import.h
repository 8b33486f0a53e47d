// Import of MagicaVoxel .vox files as a scene (format 150 with the scene-graph and material
// extensions: SIZE/XYZI models, RGBA, nTRN/nGRP/nSHP, LAYR, MATL).
//
// Placement: every shape the scene graph reaches from the root transform is placed with its
// accumulated rotation (the packed `_r` byte) and translation (`_t`, the anchor is the
// model's centre) at one animation frame (the keyframes in effect at `frame`: nTRN frame
// dictionaries and nSHP models with their `_f`); hidden nodes and layers are left out unless
// --layers names the layer. A file without a scene graph is a PACK animation: model `frame`
// at the origin. The voxels' bounding box is moved to the grid origin and cut into 16^3
// blocks. MagicaVoxel's +Z (up) becomes +Y: (x, y, z) maps to
// (x, z, size_y - 1 - y), a proper rotation, so models keep their handedness.
//
// Cameras: "default" (three-quarter view from MagicaVoxel's front) and the named views front,
// back, left, right, top, iso, then the file's rCAM cameras that convert ("file_<id>").
// Light: the file's sun and uniform sky (rOBJ/rLIT/rAIR) where present, else fixed defaults.
// docs/import.md lists every MagicaVoxel feature and what becomes of it.
//
// Colours: the RGBA chunk, else MagicaVoxel's default palette. Materials (MATL) map to the
// palette entry's roughness level, metallic level and emission level (vox_materials.cpp);
// what a scene palette cannot express is reported as dropped.
//
// Defaults that fit the content (vox_materials.cpp, chooseBakeDefaults): plain diffuse colours
// get level 7 (one 2 x 2 RDM per block, no glossy one); bake.max_hemisphere and bake.spp are
// the largest that keep the atlas and the traced paths within fixed budgets; the face light
// is on when a colour emits. The report says what was chosen and why, one line each.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "rdm/base/status.h"
#include "rdm/scene/scene.h"

namespace rdm {

struct VoxImportOptions {
  // Roughness level 0..7 of colours without a MATL, with _diffuse or _emit, and of _metal
  // without _rough. Unset: 7 for the diffuse and emissive ones (Lambert: a level-7 RDM only),
  // 5 for such metals.
  std::optional<int> roughness;
  int metallic = 0;  // metallic level of the diffuse colours
  int frame = 0;     // animation frame 0..frames-1
  // Layers (LAYR `_name` or index) to include even when hidden; an unknown one is an error.
  std::vector<std::string> layers;
  // A one-voxel-thick light grey floor under the model's footprint, kGroundMargin voxels
  // wider on each side.
  bool ground = false;
};

constexpr int kGroundMargin = 4;

// What an import did, for the user: counts and one line per mapping or loss.
struct VoxImportReport {
  int models = 0;     // models in the file
  int instances = 0;  // shapes placed
  int frames = 1;     // animation frames in the file
  int frame = 0;      // the one imported
  int materials = 0;  // MATL chunks in the file
  int hidden = 0;     // shapes left out (hidden node or layer)
  bool scene_graph = false;
  bool default_palette = false;
  uint64_t voxels = 0;  // voxels placed (after overlaps), the ground's not included
  uint64_t ground_voxels = 0;
  std::vector<std::string> mapped, dropped;  // materials; dropped: every loss
  // One line each for the sun and the sky, from the file or the defaults.
  std::vector<std::string> lights;
  // The cameras written (the standard views, each rCAM that converts).
  std::vector<std::string> cameras;
  // One line per default chosen from the content ("roughness: ...", "hemisphere: ...",
  // "spp: ...", "face light: ..."), each with its reason.
  std::vector<std::string> chosen;
};

// MagicaVoxel's default palette (used without an RGBA chunk), RGBA per index 0..255
// (index 0 is empty).
const std::array<std::array<uint8_t, 4>, 256>& voxDefaultPalette();

// Errors name the byte offset and chunk of malformed input.
Expected<Scene> importVox(const std::string& bytes, const VoxImportOptions& options = {},
                          VoxImportReport* report = nullptr);

}  // namespace rdm
