// Atlas layout (docs/spec.md section 4): the canonical packer, atlas page assembly, index.json
// and the thesis's index.txt.
#pragma once

#include <string>
#include <vector>

#include "rdm/bake.h"
#include "rdm/image.h"
#include "rdm/status.h"

namespace rdm {

constexpr int kMaxPageSize = 16384;  // lavapipe's maxImageDimension2D

struct AtlasPage {
  int width = 0, height = 0;
};

struct AtlasEntry {
  RdmId id;
  int page = 0;
  int x = 0, y = 0;  // rect is [x, y, 2 S, 3 S]
};

struct AtlasLayout {
  std::vector<AtlasPage> pages;
  std::vector<AtlasEntry> entries;  // canonical order
  long long scene_version = 1;
  double occupancy() const;
  const AtlasEntry* find(const glm::ivec3& slot, int level) const;
};

// A pure function of the RDM list: sorts it canonically, packs rows of power-of-two cells
// subdivided into quadrants, and picks the page width with the best occupancy.
AtlasLayout packCanonical(std::vector<RdmId> rdms);

// Pages of R, G, B, Z; uncovered texels are 0. `rdms` may come in any order.
std::vector<Image> assembleAtlas(const AtlasLayout& layout, const std::vector<RdmData>& rdms);

std::string indexToJson(const AtlasLayout& layout);
Expected<AtlasLayout> parseIndexJson(const std::string& text);
std::string indexToText(const AtlasLayout& layout);  // page 0 only, as in the thesis

// Writes atlas.exr (page 0; further pages atlas.page<N>.exr), index.json and index.txt into
// `dir`, each atomically. Fails with a message naming any non-finite texel, writing nothing.
Status writeAtlasOutputs(const std::string& dir, const AtlasLayout& layout,
                         const std::vector<RdmData>& rdms);
std::string atlasPageFileName(int page);

// An atlas as `writeAtlasOutputs` wrote it: the layout and every page (R, G, B, Z).
struct LoadedAtlas {
  AtlasLayout layout;
  std::vector<Image> pages;
};
// Reads index.json and every page of `dir`, refusing pages whose size differs from the index.
Expected<LoadedAtlas> readAtlasOutputs(const std::string& dir);
// The 2S x 3S texels of `entry`'s rect.
Image rdmTexels(const LoadedAtlas& atlas, const AtlasEntry& entry);

// RDM by RDM, wherever each atlas placed them: the RDMs of `a` absent from `b` (by slot
// and level) or of another size or with any texel not bit-identical, then those of `b`
// absent from `a`. Empty when both hold the same RDMs with the same texels.
std::vector<RdmId> differingRdms(const LoadedAtlas& a, const LoadedAtlas& b);

// An index belongs to a scene when it holds exactly the scene's RDMs by slot and level
// (listRdms; sizes may differ, since a bake may override max_hemisphere). Fails with
// kInvalidInput naming the first difference.
Status checkLayoutMatches(const AtlasLayout& layout, const std::vector<RdmId>& rdms);

}  // namespace rdm
