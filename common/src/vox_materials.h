// MagicaVoxel palette and material mapping for vox_import.cpp (rdm/vox_import.h).
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "rdm/scene.h"
#include "rdm/vox_import.h"

namespace rdm::vox {

using Dict = std::map<std::string, std::string>;

// Collects, over the colours used, what was mapped and what was dropped, and the emission
// power (_flux) that sets the scene's emission_scale.
class MaterialNotes {
 public:
  void mapped(const std::string& line) { mapped_.push_back(line); }
  void dropped(const std::string& what, int colour) { dropped_[what].push_back(colour); }
  void flux(double f) { fluxes_.push_back(f); }
  // emission_scale for the emitters: 4 at _flux 0, doubling per unit of _flux (the largest).
  double emissionScale() const;
  void finish(VoxImportReport& report) const;

 private:
  std::vector<std::string> mapped_;
  std::map<std::string, std::vector<int>> dropped_;
  std::vector<double> fluxes_;
};

// The scene palette entry for .vox colour `index` with its MATL properties (null: none).
PaletteEntry mapMaterial(int index, const std::array<uint8_t, 4>& rgba, const Dict* matl,
                         const VoxImportOptions& options, MaterialNotes& notes);

}  // namespace rdm::vox
