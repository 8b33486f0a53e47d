#include "vox_materials.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <set>

#include "rdm/scene/world.h"

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

// The refractive index of a glass material: `_ri` where present, else `_ior`, which
// MagicaVoxel stores as the index less 1 (0.3 for 1.3) and other writers as the index itself;
// 1.5 without either. Clamped to 1..3.
double glassIndex(const Dict& m) {
  double n = 1.5;
  if (m.count("_ri")) {
    n = number(m, "_ri", 1.5);
  } else if (m.count("_ior")) {
    const double v = number(m, "_ior", 0.5);
    n = v < 1.0 ? 1.0 + v : v;
  }
  return std::clamp(n, 1.0, 3.0);
}

// Properties this mapping reads.
const std::set<std::string> kUsed = {"_type", "_rough", "_metal", "_emit", "_flux", "_weight"};

// Why `key` of a material of `type` is lost; empty when it does not matter for the mapped
// type or carries MagicaVoxel's default: the glass line covers refraction, transparency and
// media; media properties matter only with a density _d > 0; specular tint only on metal.
std::string reason(const std::string& type, const std::string& key, const Dict& m) {
  const bool media_keys =
      key == "_att" || key == "_d" || key == "_media" || key == "_g" || key == "_media_type";
  if (type == "_glass" && (key == "_ior" || key == "_ri" || key == "_trans" || key == "_alpha"))
    return "";
  if (key == "_ior" || key == "_ri" || key == "_att" || key == "_g" || key == "_media_type")
    return "";
  if (media_keys) return number(m, "_d", 0.0) > 0 ? "participating media (not simulated)" : "";
  if (key == "_trans" || key == "_alpha") return "transparency (opaque voxels only)";
  if (key == "_spec" || key == "_sp")
    return type == "_metal" ? "specular tint (Fresnel from the base colour)" : "";
  if (key == "_ldr") return "LDR emission tweak (no equivalent)";
  if (key == "_plastic")
    return m.at(key) == "0" ? "" : "plastic flag (the BSDF is always dielectric + GGX)";
  return "no equivalent";
}

std::string describe(const PaletteEntry& e) {
  std::string text = "roughness " + std::to_string(e.roughness) + ", metallic " +
                     std::to_string(e.metallic) + ", emission " + std::to_string(e.emission);
  if (e.transmission > 0.0) {
    char glass[64];
    std::snprintf(glass, sizeof(glass), ", glass: transmission %.2f, ior %.2f", e.transmission,
                  e.ior);
    text += glass;
  }
  return text;
}

}  // namespace

void MaterialNotes::level(const std::string& kind, int level, const std::string& why) {
  const int rank = kind == "diffuse" ? 0 : kind == "emissive" ? 1 : kind == "metal" ? 2 : 3;
  ++levels_[{rank, kind, why}][level];
}

std::string MaterialNotes::roughnessLine() const {
  if (levels_.empty()) return "roughness: no colour used";
  std::string line = "roughness:", last_why;
  for (const auto& [key, counts] : levels_) {
    const auto& [rank, kind, why] = key;
    if (!last_why.empty()) line += why == last_why ? "," : " (" + last_why + ");";
    last_why = why;
    int colours = 0;
    std::string levels;
    for (const auto& [level, count] : counts) {
      colours += count;
      levels += (levels.empty() ? "" : ", ") + std::to_string(level);
      if (counts.size() > 1 && count > 1) levels += " (x" + std::to_string(count) + ")";
    }
    line += (counts.size() > 1 ? " levels " : " level ") + levels + " for " +
            std::to_string(colours) + " " + kind + (colours > 1 ? " colours" : " colour");
  }
  return line + " (" + last_why + ")";
}

namespace {
double largestFlux(const std::map<int, std::pair<double, double>>& emitters) {
  double flux = -1e9;
  for (const auto& [colour, e] : emitters) flux = std::max(flux, e.second);
  return flux;
}
}  // namespace

double MaterialNotes::emissionScale() const {
  if (emitters_.empty()) return 1.0;
  return 4.0 * std::exp2(std::clamp(largestFlux(emitters_), -8.0, 8.0));
}

int MaterialNotes::emissionLevel(int colour) const {
  auto it = emitters_.find(colour);
  if (it == emitters_.end()) return -1;
  const auto [emit, flux] = it->second;
  const double relative = emit * std::exp2(std::max(flux - largestFlux(emitters_), -30.0));
  return std::max(1, vox::level(relative, 3));
}

void MaterialNotes::finish(VoxImportReport& report) const {
  for (Mapped m : mapped_) {
    if (const int emission = emissionLevel(m.colour); emission >= 0) m.entry.emission = emission;
    report.mapped.push_back("colour " + std::to_string(m.colour) + " " + m.type + " -> " +
                            describe(m.entry));
  }
  report.chosen.push_back(roughnessLine());
  for (const auto& [what_why, colours] : dropped_) {
    const auto& [what, why] = what_why;
    std::string list;
    for (size_t i = 0; i < colours.size() && i < 8; ++i) {
      if (i) list += ' ';
      list += std::to_string(colours[i]);
    }
    if (colours.size() > 8) list += " ...";
    std::string line = what + " on " + std::to_string(colours.size()) +
                       (colours.size() > 1 ? " colours (" : " colour (") + list + "): " + why;
    report.dropped.push_back(std::move(line));
  }
  std::set<double> fluxes;
  for (const auto& [colour, e] : emitters_) fluxes.insert(e.second);
  if (fluxes.size() > 1) {
    report.dropped.push_back(
        "per-material _flux (approximate): emission level = 3 x _emit x 2^(_flux - largest "
        "_flux), rounded to 1..3, so ratios under 1/6 become 1/3; emission_scale from the "
        "largest _flux");
  }
}

PaletteEntry mapMaterial(int index, const std::array<uint8_t, 4>& rgba, const Dict* matl,
                         const VoxImportOptions& options, MaterialNotes& notes) {
  const int diffuse = options.roughness.value_or(kDiffuseLevel);
  const std::string why_diffuse = options.roughness
                                      ? "--roughness " + std::to_string(*options.roughness)
                                      : "default: Lambert, no glossy RDM";
  PaletteEntry e{{rgba[0], rgba[1], rgba[2]}, diffuse, options.metallic, 0};
  if (rgba[3] < 255) notes.dropped("palette alpha < 255", "opaque", index);
  const std::string type = matl && matl->count("_type") ? matl->at("_type") : "_diffuse";
  if (!matl || type == "_diffuse") {
    notes.level("diffuse", diffuse, why_diffuse);
    return e;
  }
  const Dict& m = *matl;
  if (type == "_metal" || type == "_blend") {
    const int fallback = options.roughness.value_or(kMetalFallbackLevel);
    e.roughness = level(number(m, "_rough", fallback / 7.0), 7);
    e.metallic = level(number(m, "_metal", number(m, "_weight", 1.0)), 3);
    notes.level("metal", e.roughness, "from MATL");
  } else if (type == "_glass") {
    e.roughness = level(number(m, "_rough", 0.0), 7);
    e.metallic = 0;
    e.transmission = std::clamp(number(m, "_trans", number(m, "_alpha", 1.0)), 0.0, 1.0);
    e.ior = glassIndex(m);
    if (e.roughness > 0)
      notes.dropped("_rough on glass", "the glass itself is smooth (the rest stays rough)", index);
    notes.level("glass", e.roughness, "from MATL");
  } else if (type == "_emit") {
    const double emit = number(m, "_emit", number(m, "_weight", 1.0));
    e.emission = emit > 0 ? std::max(1, level(emit, 3)) : 0;
    if (e.emission > 0) notes.emitter(index, emit, number(m, "_flux", 0.0));
    notes.level(e.emission > 0 ? "emissive" : "diffuse", diffuse, why_diffuse);
  } else {
    notes.dropped("material type " + type, "imported as diffuse", index);
    notes.level("diffuse", diffuse, why_diffuse);
    return e;
  }
  for (const auto& [key, value] : m) {
    if (kUsed.count(key)) continue;
    if (std::string why = reason(type, key, m); !why.empty()) notes.dropped(key, why, index);
  }
  notes.mapped(index, type, e);
  return e;
}

namespace {

// What the bake defaults depend on, from the placed voxels.
struct Content {
  std::vector<uint8_t> level_masks;  // per non-empty slot: bit r when level r has an RDM
  int emissive_colours = 0;          // palette entries with emission > 0 that voxels use
  uint64_t exposed_faces = 0;        // docs/spec.md section 3.2; counted only with emitters
};

using SlotVoxels = std::map<std::array<int, 3>, std::array<uint8_t, 4096>>;

bool solidAt(const SlotVoxels& slots, const std::array<int, 3>& voxel) {
  std::array<int, 3> slot{}, local{};
  for (size_t a = 0; a < 3; ++a) {
    if (voxel[a] < 0) return false;  // outside the grid, which starts at 0
    slot[a] = voxel[a] / 16, local[a] = voxel[a] % 16;
  }
  auto it = slots.find(slot);
  return it != slots.end() && it->second[size_t(local[0] + 16 * local[1] + 256 * local[2])] != 0;
}

uint64_t exposedFaces(const SlotVoxels& slots) {
  constexpr int kSteps[6][3] = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
  uint64_t faces = 0;
  for (const auto& [slot, voxels] : slots) {
    for (int i = 0; i < 4096; ++i) {
      if (voxels[size_t(i)] == 0) continue;
      const std::array<int, 3> local{i % 16, (i / 16) % 16, i / 256};
      for (const auto& step : kSteps) {
        std::array<int, 3> next{};
        bool inside = true;  // the neighbour is in this slot: no lookup
        for (size_t a = 0; a < 3; ++a) {
          next[a] = local[a] + step[a];
          inside = inside && next[a] >= 0 && next[a] < 16;
        }
        const bool solid = inside ? voxels[size_t(next[0] + 16 * next[1] + 256 * next[2])] != 0
                                  : solidAt(slots, {16 * slot[0] + next[0], 16 * slot[1] + next[1],
                                                    16 * slot[2] + next[2]});
        faces += solid ? 0 : 1;
      }
    }
  }
  return faces;
}

Content gather(const Scene& scene) {
  Content c;
  SlotVoxels slots;
  std::set<int> emissive;
  for (const Placement& p : scene.placements) {
    const auto voxels = orientedVoxels(scene.blocks.at(p.block), p.rot);
    uint8_t mask = 0x80;
    for (uint8_t v : voxels) {
      if (v == 0) continue;
      const PaletteEntry& e = scene.palette[size_t(v - 1)];
      mask |= uint8_t(1u << e.roughness);
      if (e.emission > 0) emissive.insert(v);
    }
    c.level_masks.push_back(mask);
    slots[p.at] = voxels;
  }
  c.emissive_colours = int(emissive.size());
  if (c.emissive_colours > 0) c.exposed_faces = exposedFaces(slots);
  return c;
}

uint64_t hemisphereSize(int level, int max_hemisphere) {
  return uint64_t(std::max(2, std::min(1 << (8 - level), max_hemisphere)));
}

// Texels of every RDM (docs/spec.md section 3: S(r) = max(2, min(2^(8-r), max_hemisphere))).
uint64_t atlasTexels(const Content& c, int max_hemisphere) {
  uint64_t texels = 0;
  for (uint8_t mask : c.level_masks) {
    for (int r = 0; r < 8; ++r) {
      const uint64_t size = hemisphereSize(r, max_hemisphere);
      texels += (mask >> r & 1) ? 6 * size * size : 0;
    }
  }
  return texels;
}

// Paths per sample: per face the prefiltered map at the finest rough level (section 3.1), or
// the naive 2 x 2 level-7 RDM of a block with no rough level.
uint64_t tracedTexels(const Content& c, int max_hemisphere) {
  uint64_t texels = 0;
  for (uint8_t mask : c.level_masks) {
    const unsigned rough = mask & 0x7fu;
    const uint64_t size = rough ? hemisphereSize(std::countr_zero(rough), max_hemisphere) : 2;
    texels += 6 * size * size;
  }
  return texels;
}

std::string human(uint64_t n) {
  char text[32];
  if (n < 10000) return std::to_string(n);
  std::snprintf(text, sizeof text, n < 1000000 ? "%.1fk" : "%.1fM",
                double(n) / (n < 1000000 ? 1e3 : 1e6));
  return text;
}

int largestPowerOfTwo(int lo, int hi, const auto& fits) {
  for (int v = hi; v > lo; v /= 2) {
    if (fits(v)) return v;
  }
  return lo;
}

std::string hemisphereLine(const Content& c, int h) {
  size_t glossy = 0, rdms = 0;
  for (uint8_t mask : c.level_masks) {
    glossy += (mask & 0x7f) != 0 ? 1 : 0;
    rdms += size_t(std::popcount(mask));
  }
  const std::string blocks = std::to_string(c.level_masks.size());
  if (glossy == 0)
    return "hemisphere: max 256 (no glossy block: " + blocks + " RDMs, each 2 x 2 at level 7, " +
           human(atlasTexels(c, h)) + " texels)";
  std::string line = "hemisphere: max " + std::to_string(h) + " (" + std::to_string(glossy) +
                     " of " + blocks + " blocks glossy: " + std::to_string(rdms) + " RDMs, " +
                     human(atlasTexels(c, h)) + " texels, budget " + human(kTexelBudget);
  if (h < 256)
    line += "; max " + std::to_string(2 * h) + " would be " + human(atlasTexels(c, 2 * h)) +
            " texels, " + human(kMinSpp * tracedTexels(c, 2 * h)) + " paths at " +
            std::to_string(kMinSpp) + " spp, budget " + human(kPathBudget);
  return line + ")";
}

std::string sppLine(uint64_t traced, int spp) {
  const uint64_t paths = traced * uint64_t(spp);
  const char* why = spp == 256             ? "the most"
                    : paths <= kPathBudget ? "the most within the budget"
                                           : "the least, over the budget";
  return "spp: " + std::to_string(spp) + " (" + why + ": " + human(traced) + " traced texels x " +
         std::to_string(spp) + " = " + human(paths) + " paths, budget " + human(kPathBudget) + ")";
}

}  // namespace

void chooseBakeDefaults(Scene& scene, std::vector<std::string>& lines) {
  const Content c = gather(scene);
  BakeSettings& bake = scene.bake;
  bake.max_hemisphere = largestPowerOfTwo(2, 256, [&](int h) {
    return atlasTexels(c, h) <= kTexelBudget && kMinSpp * tracedTexels(c, h) <= kPathBudget;
  });
  lines.push_back(hemisphereLine(c, bake.max_hemisphere));
  const uint64_t traced = tracedTexels(c, bake.max_hemisphere);
  bake.spp = largestPowerOfTwo(kMinSpp, 256, [&](int spp) { return spp * traced <= kPathBudget; });
  lines.push_back(sppLine(traced, bake.spp));
  if (c.emissive_colours == 0) {
    scene.face_light_spp = 0;
    lines.push_back("face light: off (no emissive colour; rdm bake --face-light N adds one)");
    return;
  }
  scene.face_light_spp = largestPowerOfTwo(kMinFaceLightSpp, kMaxFaceLightSpp, [&](int spp) {
    return spp * c.exposed_faces <= kFaceLightPathBudget;
  });
  lines.push_back("face light: " + std::to_string(scene.face_light_spp) + " spp (" +
                  std::to_string(c.emissive_colours) + " emissive colour" +
                  (c.emissive_colours > 1 ? "s; " : "; ") + human(c.exposed_faces) +
                  " exposed faces x " + std::to_string(scene.face_light_spp) + " = " +
                  human(c.exposed_faces * uint64_t(scene.face_light_spp)) + " paths, budget " +
                  human(kFaceLightPathBudget) + ")");
}

}  // namespace vox
}  // namespace rdm
