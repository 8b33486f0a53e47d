// How atlas pages store radiance (rdm/atlas/atlas.h, docs/spec.md section 4): float32, or half
// (or bc6h) with a power-of-two scale per face tile. Scaling by 2^-e is exact in float; the only
// loss is half's rounding (relative 2^-11) and values below half's range in a tile scaled down.
#include <algorithm>
#include <cmath>
#include <map>

#include "rdm/atlas/atlas.h"

namespace rdm {
namespace {

int exponentFor(float max_radiance) {
  int e = 0;
  while (e < kMaxTileExponent && std::ldexp(max_radiance, -e) > kHalfMax) ++e;
  return e;
}

}  // namespace

void scaleTile(Image& page, const FaceTile& t, int size, int exponent) {
  if (exponent == 0) return;
  for (int y = t.y; y < t.y + size; ++y)
    for (int x = t.x; x < t.x + size; ++x)
      for (int c = 0; c < 3; ++c) page.at(x, y, c) = std::ldexp(page.at(x, y, c), exponent);
}

AtlasLayout withTileExponents(AtlasLayout layout, const std::vector<RdmDigest>& rdms) {
  for (AtlasEntry& e : layout.entries) {
    for (FaceTile& t : e.faces) t.exponent = 0;
  }
  if (layout.radiance == RadianceFormat::kFloat32) return layout;
  std::map<RdmId, const RdmDigest*, bool (*)(const RdmId&, const RdmId&)> by_id(canonicalLess);
  for (const RdmDigest& d : rdms) by_id[d.id] = &d;
  for (AtlasEntry& e : layout.entries) {
    auto it = by_id.find(e.id);
    if (it == by_id.end()) continue;
    for (int f = 0; f < 6; ++f) {
      FaceTile& t = e.faces[size_t(f)];
      if (t.stored()) t.exponent = exponentFor(it->second->face_max[size_t(f)]);
    }
  }
  return layout;
}

void restoreRadiance(const AtlasLayout& layout, int page_index, Image& page) {
  for (const AtlasEntry& e : layout.entries) {
    for (const FaceTile& t : e.faces) {
      if (t.page == page_index) scaleTile(page, t, e.id.size, t.exponent);
    }
  }
}

Expected<RadianceFormat> parseRadianceFormat(const std::string& name) {
  if (name == "float32") return RadianceFormat::kFloat32;
  if (name == "half") return RadianceFormat::kHalf;
  if (name == "bc6h") return RadianceFormat::kBc6h;
  return Status::invalid("radiance", "radiance format '" + name + "' is not float32, half or bc6h");
}

const char* radianceFormatName(RadianceFormat format) {
  switch (format) {
    case RadianceFormat::kHalf:
      return "half";
    case RadianceFormat::kBc6h:
      return "bc6h";
    case RadianceFormat::kFloat32:
      break;
  }
  return "float32";
}

}  // namespace rdm
