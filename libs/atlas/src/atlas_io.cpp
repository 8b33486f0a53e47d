#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <sstream>

#include <nlohmann/json.hpp>

#include "rdm/atlas/atlas.h"
#include "rdm/atlas/atlas_json.h"
#include "rdm/base/check.h"
#include "rdm/base/file_util.h"
#include "rdm/image/exr_io.h"
#include "rdm/transport/rdm_shared_cpp.h"

namespace rdm {
namespace {

using nlohmann::json;

struct RdmKeyLess {
  bool operator()(const RdmId& a, const RdmId& b) const { return canonicalLess(a, b); }
};

}  // namespace

Status forEachRdmOnPage(const AtlasLayout& layout, int page, const RdmSource& source,
                        const std::function<void(const AtlasEntry&, const RdmData&)>& use) {
  std::map<RdmId, size_t, RdmKeyLess> by_id;
  const std::vector<RdmId> ids = source.ids();
  for (size_t i = 0; i < ids.size(); ++i) by_id[ids[i]] = i;
  for (const AtlasEntry& e : layout.entries) {
    const bool on_page = std::any_of(e.faces.begin(), e.faces.end(),
                                     [&](const FaceTile& t) { return t.page == page; });
    auto it = by_id.find(e.id);
    if (!on_page || it == by_id.end()) continue;
    if (Status s = source.visit(it->second, [&](const RdmData& rdm) { use(e, rdm); }); !s) return s;
  }
  return {};
}

Expected<Image> assembleAtlasPage(const AtlasLayout& layout, int page, const RdmSource& source) {
  const AtlasPage& p = layout.pages.at(size_t(page));
  Image out(p.width, p.height, 4);
  Status s = forEachRdmOnPage(layout, page, source, [&](const AtlasEntry& e, const RdmData& rdm) {
    const int size = e.id.size;
    RDM_CHECK(rdm.image.width == 2 * size && rdm.image.height == 3 * size);
    for (int f = 0; f < 6; ++f) {
      const FaceTile& t = e.faces[size_t(f)];
      if (t.page != page) continue;
      copyTexels(rdm.image, size * (f % 2), size * (f / 2), out, t.x, t.y, size, size);
      scaleTile(out, t, size, -t.exponent);
    }
  });
  if (!s) return s;
  return out;
}

std::vector<Image> assembleAtlas(const AtlasLayout& layout, const std::vector<RdmData>& rdms) {
  const MemoryRdmSource source(rdms);
  std::vector<Image> pages;
  for (size_t p = 0; p < layout.pages.size(); ++p)
    pages.push_back(std::move(*assembleAtlasPage(layout, int(p), source)));  // memory: no IO
  return pages;
}

json atlasEntryJson(const AtlasEntry& e) {
  json faces = json::array();
  for (const FaceTile& t : e.faces)
    faces.push_back(!t.stored()       ? json(nullptr)
                    : t.exponent == 0 ? json::array({t.page, t.x, t.y})
                                      : json::array({t.page, t.x, t.y, t.exponent}));
  return {{"slot", {e.id.slot.x, e.id.slot.y, e.id.slot.z}},
          {"level", e.id.level},
          {"size", e.id.size},
          {"faces", std::move(faces)}};
}

AtlasEntry atlasEntryOf(const json& j) {
  AtlasEntry e;
  const json& s = j.at("slot");
  e.id.slot = {s.at(0).get<int>(), s.at(1).get<int>(), s.at(2).get<int>()};
  e.id.level = j.at("level").get<int>();
  e.id.size = j.at("size").get<int>();
  const json& faces = j.at("faces");
  if (!faces.is_array() || faces.size() != 6)
    throw json::type_error::create(302, "faces must be an array of 6", &faces);
  for (size_t f = 0; f < 6; ++f) {
    if (faces[f].is_null()) continue;
    const json& t = faces[f];
    e.faces[f] = {t.at(0).get<int>(), t.at(1).get<int>(), t.at(2).get<int>(),
                  t.size() > 3 ? t.at(3).get<int>() : 0};
    if (e.faces[f].page < 0) throw json::type_error::create(302, "a face's page must be >= 0", &t);
    if (e.faces[f].exponent < 0 || e.faces[f].exponent > kMaxTileExponent)
      throw json::type_error::create(
          302, "a face's exponent must be 0.." + std::to_string(kMaxTileExponent), &t);
  }
  return e;
}

std::string indexToJson(const AtlasLayout& layout) {
  json j;
  j["format"] = "rdm-atlas";
  j["version"] = kAtlasIndexVersion;
  j["sky_depth"] = shared::kSkyDepth;
  j["scene_version"] = layout.scene_version;
  j["radiance"] = radianceFormatName(layout.radiance);
  if (!layout.lighting.empty()) j["lighting"] = layout.lighting;
  j["pages"] = json::array();
  for (const AtlasPage& p : layout.pages)
    j["pages"].push_back({{"width", p.width}, {"height", p.height}});
  j["rdms"] = json::array();
  for (const AtlasEntry& e : layout.entries) j["rdms"].push_back(atlasEntryJson(e));
  return j.dump(1) + "\n";
}

Expected<AtlasLayout> parseIndexJson(const std::string& text) {
  try {
    json j = json::parse(text);
    if (j.at("format") != "rdm-atlas")
      return Status::invalid("index.json", "index.json: not an rdm-atlas index");
    const int version = j.at("version").get<int>();
    if (version != kAtlasIndexVersion)
      return Status::invalid("index.json",
                             "index.json: rdm-atlas version " + std::to_string(version) +
                                 (version < kAtlasIndexVersion
                                      ? " was written before the compact layout (per-face tiles, "
                                        "version 2); bake the scene again"
                                      : " is newer than this program reads (" +
                                            std::to_string(kAtlasIndexVersion) + ")"));
    AtlasLayout layout;
    layout.scene_version = j.value("scene_version", 1LL);
    auto radiance = parseRadianceFormat(j.value("radiance", std::string("float32")));
    if (!radiance) return Status::invalid("index.json", "index.json: " + radiance.error());
    layout.radiance = *radiance;
    if (j.contains("lighting")) layout.lighting = j["lighting"].get<LightingFingerprint>();
    for (const json& p : j.at("pages"))
      layout.pages.push_back({p.at("width").get<int>(), p.at("height").get<int>()});
    for (const json& r : j.at("rdms")) {
      AtlasEntry e = atlasEntryOf(r);
      if (!tilesFit(e, layout.pages))
        return Status::invalid("index.json", "index.json: rdms[" +
                                                 std::to_string(layout.entries.size()) +
                                                 "]: a face tile lies outside its page");
      layout.entries.push_back(e);
    }
    return layout;
  } catch (const std::exception& e) {
    return Status::invalid("index.json", std::string("index.json: ") + e.what());
  }
}

std::string indexToText(const AtlasLayout& layout) {
  std::ostringstream os;
  int count = 0;
  for (const AtlasEntry& e : layout.entries)
    for (const FaceTile& t : e.faces) count += t.page == 0 ? 1 : 0;
  const AtlasPage page = layout.pages.empty() ? AtlasPage{} : layout.pages[0];
  os << count << " " << page.width << " " << page.height << "\n";
  for (const AtlasEntry& e : layout.entries) {
    for (int f = 0; f < 6; ++f) {
      const FaceTile& t = e.faces[size_t(f)];
      if (t.page != 0) continue;
      os << e.id.slot.x << " " << e.id.slot.y << " " << e.id.slot.z << " " << e.id.level << " " << f
         << " " << t.x << " " << t.y << " " << e.id.size << "\n";
    }
  }
  return os.str();
}

std::string atlasPageFileName(int page) {
  return page == 0 ? "atlas.exr" : "atlas.page" + std::to_string(page) + ".exr";
}

namespace {

// Page `page` (R, G, B, Z as stored) in the files of layout.radiance.
Status writeAtlasPage(const std::string& dir, const AtlasLayout& layout, int page, Image& texels,
                      const Bc6hEncodeFn& bc6h, Bc6hReuse* reuse) {
  if (layout.radiance == RadianceFormat::kBc6h)
    return writeBc6hAtlasPage(dir, layout, page, texels, bc6h, reuse);
  const std::vector<std::string> half = layout.radiance == RadianceFormat::kHalf
                                            ? std::vector<std::string>{"R", "G", "B"}
                                            : std::vector<std::string>{};
  return writeExr(dir + "/" + atlasPageFileName(page), texels, kRgbzChannels, half);
}

}  // namespace

Status writeAtlasOutputs(const std::string& dir, const AtlasLayout& packed, const RdmSource& source,
                         const Bc6hEncodeFn& bc6h, Bc6hReuse* reuse) {
  const auto digests = source.digests();
  if (!digests) return digests.status();
  for (const RdmDigest& d : *digests) {
    if (!d.finite) {
      return Status::error("non-finite texel in RDM slot (" + std::to_string(d.id.slot.x) + "," +
                           std::to_string(d.id.slot.y) + "," + std::to_string(d.id.slot.z) +
                           ") level " + std::to_string(d.id.level) + "; nothing written");
    }
  }
  if (Status s = makeDirectories(dir); !s) return s;
  RDM_CHECK(packed.radiance != RadianceFormat::kBc6h || blockAligned(packed));
  const AtlasLayout layout = withTileExponents(packed, *digests);
  for (size_t p = 0; p < layout.pages.size(); ++p) {
    auto page = assembleAtlasPage(layout, int(p), source);
    if (!page) return page.status();
    if (Status s = writeAtlasPage(dir, layout, int(p), *page, bc6h, reuse); !s) return s;
  }
  if (Status s = writeFileAtomic(dir + "/index.txt", indexToText(layout)); !s) return s;
  return writeFileAtomic(dir + "/index.json", indexToJson(layout));
}

Status writeAtlasOutputs(const std::string& dir, const AtlasLayout& layout,
                         const std::vector<RdmData>& rdms, const Bc6hEncodeFn& bc6h) {
  return writeAtlasOutputs(dir, layout, MemoryRdmSource(rdms), bc6h);
}

namespace {

std::string rdmName(const RdmId& id) {
  return "slot (" + std::to_string(id.slot.x) + ", " + std::to_string(id.slot.y) + ", " +
         std::to_string(id.slot.z) + ") level " + std::to_string(id.level);
}

}  // namespace

Status checkLayoutMatches(const AtlasLayout& layout, const std::vector<RdmId>& rdms) {
  const std::string counts = " (the scene has " + std::to_string(rdms.size()) +
                             " RDMs, the index " + std::to_string(layout.entries.size()) + ")";
  for (const RdmId& id : rdms) {
    const AtlasEntry* e = layout.find(id.slot, id.level);
    if (!e) return Status::invalid("index", "the index has no RDM at " + rdmName(id) + counts);
  }
  if (layout.entries.size() != rdms.size())
    return Status::invalid("index", "the index holds RDMs the scene does not have" + counts);
  return {};
}

}  // namespace rdm
