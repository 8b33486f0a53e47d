#include "vox_materials.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <set>

namespace rdm {

// Built from the structure of the table in MagicaVoxel's format description: index 0 empty;
// 1..215 the 6^3 cube of channel values {ff, cc, 99, 66, 33, 00} without black, red
// slowest and blue fastest; then ramps of ten values {ee, dd, bb, aa, 88, 77, 55, 44, 22,
// 11} in red, green, blue and grey.
const std::array<std::array<uint8_t, 4>, 256>& voxDefaultPalette() {
  static const std::array<std::array<uint8_t, 4>, 256> palette = [] {
    std::array<std::array<uint8_t, 4>, 256> p{};
    constexpr uint8_t kCube[6] = {0xff, 0xcc, 0x99, 0x66, 0x33, 0x00};
    constexpr uint8_t kRamp[10] = {0xee, 0xdd, 0xbb, 0xaa, 0x88, 0x77, 0x55, 0x44, 0x22, 0x11};
    int i = 1;
    for (int r = 0; r < 6; ++r)
      for (int g = 0; g < 6; ++g)
        for (int b = 0; b < 6; ++b) {
          if (i <= 215) p[size_t(i++)] = {kCube[r], kCube[g], kCube[b], 0xff};
        }
    for (int channel = 0; channel < 4; ++channel)
      for (uint8_t v : kRamp) {
        std::array<uint8_t, 4> c{0, 0, 0, 0xff};
        if (channel == 3) {
          c = {v, v, v, 0xff};
        } else {
          c[size_t(channel)] = v;
        }
        p[size_t(i++)] = c;
      }
    return p;
  }();
  return palette;
}

namespace vox {
namespace {

// Properties this mapping reads; any other property of a non-diffuse material is dropped.
const std::set<std::string> kUsed = {"_type", "_rough", "_metal", "_emit", "_flux", "_weight"};

std::string reason(const std::string& key) {
  if (key == "_ior" || key == "_ri") return "refraction index (no transmission)";
  if (key == "_trans" || key == "_alpha") return "transparency (opaque voxels only)";
  if (key == "_att" || key == "_d" || key == "_media" || key == "_g" || key == "_media_type")
    return "participating media (not simulated)";
  if (key == "_spec" || key == "_sp") return "specular tint (Fresnel from the base colour)";
  if (key == "_ldr") return "LDR emission tweak";
  if (key == "_plastic") return "plastic flag (the BSDF is always dielectric + GGX)";
  return "no equivalent";
}

double number(const Dict& d, const std::string& key, double fallback) {
  auto it = d.find(key);
  if (it == d.end()) return fallback;
  char* end = nullptr;
  const double v = std::strtod(it->second.c_str(), &end);
  return end != it->second.c_str() && std::isfinite(v) ? v : fallback;
}

int level(double value01, int levels) {
  return std::clamp(int(std::lround(std::clamp(value01, 0.0, 1.0) * levels)), 0, levels);
}

std::string describe(const PaletteEntry& e) {
  return "roughness " + std::to_string(e.roughness) + ", metallic " + std::to_string(e.metallic) +
         ", emission " + std::to_string(e.emission);
}

}  // namespace

double MaterialNotes::emissionScale() const {
  if (fluxes_.empty()) return 1.0;
  return 4.0 * std::exp2(*std::max_element(fluxes_.begin(), fluxes_.end()));
}

void MaterialNotes::finish(VoxImportReport& report) const {
  report.mapped.insert(report.mapped.end(), mapped_.begin(), mapped_.end());
  for (const auto& [what, colours] : dropped_) {
    std::string list;
    for (size_t i = 0; i < colours.size() && i < 8; ++i) {
      if (i) list += ' ';
      list += std::to_string(colours[i]);
    }
    if (colours.size() > 8) list += " ...";
    std::string line = what;
    line += colours.size() > 1 ? " (colours " : " (colour ";
    line += list;
    line += ")";
    report.dropped.push_back(std::move(line));
  }
  if (fluxes_.size() > 1 && *std::max_element(fluxes_.begin(), fluxes_.end()) !=
                                *std::min_element(fluxes_.begin(), fluxes_.end())) {
    report.dropped.push_back(
        "per-material _flux: one emission_scale for the scene, from the largest _flux");
  }
}

PaletteEntry mapMaterial(int index, const std::array<uint8_t, 4>& rgba, const Dict* matl,
                         const VoxImportOptions& options, MaterialNotes& notes) {
  PaletteEntry e{{rgba[0], rgba[1], rgba[2]}, options.roughness, options.metallic, 0};
  if (rgba[3] < 255) notes.dropped("palette alpha < 255: opaque", index);
  const std::string type = matl && matl->count("_type") ? matl->at("_type") : "_diffuse";
  if (!matl || type == "_diffuse") return e;
  const Dict& m = *matl;
  if (type == "_metal" || type == "_blend") {
    e.roughness = level(number(m, "_rough", e.roughness / 7.0), 7);
    e.metallic = level(number(m, "_metal", number(m, "_weight", 1.0)), 3);
  } else if (type == "_glass") {
    e.roughness = level(number(m, "_rough", 0.0), 7);
    e.metallic = 0;
    notes.dropped("_glass transmission: an opaque smooth dielectric", index);
  } else if (type == "_emit") {
    const double emit = number(m, "_emit", number(m, "_weight", 1.0));
    e.emission = emit > 0 ? std::max(1, level(emit, 3)) : 0;
    if (e.emission > 0) notes.flux(number(m, "_flux", 0.0));
  } else {
    notes.dropped("material type " + type + ": diffuse", index);
    return e;
  }
  for (const auto& [key, value] : m) {
    if (!kUsed.count(key)) notes.dropped(key + ": " + reason(key), index);
  }
  notes.mapped("colour " + std::to_string(index) + " " + type + " -> " + describe(e));
  return e;
}

}  // namespace vox
}  // namespace rdm
