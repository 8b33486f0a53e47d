// MagicaVoxel palette and material mapping for vox_import.cpp (rdm/scene/vox_import.h).
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "rdm/scene/scene.h"
#include "rdm/scene/vox_import.h"

namespace rdm::vox {

using Dict = std::map<std::string, std::string>;

// Roughness level of diffuse and emissive colours without --roughness: Lambert needs only the
// level-7 RDM; and of a _metal without _rough (MagicaVoxel always writes one).
constexpr int kDiffuseLevel = 7;
constexpr int kMetalFallbackLevel = 5;

// Collects, over the colours used, what was mapped and what was dropped, the roughness level
// each kind of material got, and the emission power (_flux) that sets the scene's
// emission_scale.
class MaterialNotes {
 public:
  // Colour `colour` of MATL `type` became `entry` (its emission level as emissionLevel says).
  void mapped(int colour, const std::string& type, const PaletteEntry& entry) {
    mapped_.push_back({colour, type, entry});
  }
  // A colour of `kind` ("diffuse", "metal", "glass", "emissive") got roughness `level`, for
  // `why` ("from MATL", "default: ...", "--roughness N").
  void level(const std::string& kind, int level, const std::string& why);
  // "roughness: level 7 for 12 diffuse colours (default: ...), level 3 for 2 metal colours
  // (from MATL)": each kind's levels, grouped by why.
  std::string roughnessLine() const;
  // A loss of `what` ("_glass", "_ldr") on `colour`, reported once as "WHAT on N colours
  // (LIST): WHY".
  void dropped(const std::string& what, const std::string& why, int colour) {
    dropped_[{what, why}].push_back(colour);
  }
  // An emissive .vox colour with MATL `_emit` (0..1) and `_flux` (MagicaVoxel's power steps).
  void emitter(int colour, double emit, double flux) { emitters_[colour] = {emit, flux}; }
  // emission_scale for the emitters: 4 at _flux 0, doubling per unit of _flux (the largest).
  double emissionScale() const;
  // The emission level of an emissive colour relative to the brightest _flux: round(3 x _emit
  // x 2^(_flux - largest _flux)), at least 1; -1 for a colour that does not emit.
  int emissionLevel(int colour) const;
  void finish(VoxImportReport& report) const;

 private:
  struct Mapped {
    int colour = 0;
    std::string type;
    PaletteEntry entry;
  };
  std::vector<Mapped> mapped_;
  std::map<std::pair<std::string, std::string>, std::vector<int>> dropped_;
  std::map<int, std::pair<double, double>> emitters_;  // colour -> _emit, _flux
  // (kind's rank in the report, kind, why) -> level -> colours
  std::map<std::tuple<int, std::string, std::string>, std::map<int, int, std::greater<>>> levels_;
};

// The scene palette entry for .vox colour `index` with its MATL properties (null: none).
PaletteEntry mapMaterial(int index, const std::array<uint8_t, 4>& rgba, const Dict* matl,
                         const VoxImportOptions& options, MaterialNotes& notes);

// Budgets of the bake defaults below. Atlas texels: 2^22 is about 120 MB in a bake (28 bytes a
// texel, docs/deploy.md). Traced paths: 2^25 is 11-17 s on 2 cores at the 2-3 M paths/s of a
// diffuse model (docs/performance.md, "Import defaults"); the face light gets an eighth.
constexpr uint64_t kTexelBudget = uint64_t(1) << 22;
constexpr uint64_t kPathBudget = uint64_t(1) << 25;
constexpr uint64_t kFaceLightPathBudget = uint64_t(1) << 22;
constexpr int kMinSpp = 16, kMinFaceLightSpp = 4, kMaxFaceLightSpp = 64;

// Sets scene.bake.max_hemisphere, scene.bake.spp and scene.face_light_spp from the imported
// content and appends one line each, with the reason, to `lines`:
// - max_hemisphere: the largest power of two in 2..256 whose atlas (every RDM of every
//   non-empty slot, docs/spec.md section 3) holds at most kTexelBudget texels and can be
//   traced at kMinSpp within kPathBudget; a model of many glossy blocks gets smaller maps.
// - spp: the largest power of two in kMinSpp..256 whose traced paths (per face, the
//   prefiltered map of a glossy block, the 2 x 2 level-7 RDM of a diffuse one) fit
//   kPathBudget; never below kMinSpp.
// - face_light_spp: 0 without an emissive colour (no glow to show); else the largest power
//   of two in kMinFaceLightSpp..kMaxFaceLightSpp with exposed faces x spp within
//   kFaceLightPathBudget.
void chooseBakeDefaults(Scene& scene, std::vector<std::string>& lines);

}  // namespace rdm::vox
