#include <cmath>
#include <cstring>
#include <map>
#include <sstream>

#include <nlohmann/json.hpp>

#include "rdm/atlas.h"
#include "rdm/atlas_json.h"
#include "rdm/exr_io.h"
#include "rdm/file_util.h"
#include "rdm/rdm_shared_cpp.h"

namespace rdm {
namespace {

using nlohmann::json;

struct RdmKeyLess {
  bool operator()(const RdmId& a, const RdmId& b) const { return canonicalLess(a, b); }
};

}  // namespace

std::vector<Image> assembleAtlas(const AtlasLayout& layout, const std::vector<RdmData>& rdms) {
  std::vector<Image> pages;
  for (const AtlasPage& p : layout.pages) pages.emplace_back(p.width, p.height, 4);
  std::map<RdmId, const RdmData*, RdmKeyLess> by_id;
  for (const RdmData& d : rdms) by_id[d.id] = &d;
  for (const AtlasEntry& e : layout.entries) {
    auto it = by_id.find(e.id);
    if (it == by_id.end()) continue;
    const Image& image = it->second->image;
    RDM_CHECK(image.width == 2 * e.id.size && image.height == 3 * e.id.size);
    const int s = e.id.size;
    for (int f = 0; f < 6; ++f) {
      const FaceTile& t = e.faces[size_t(f)];
      if (!t.stored()) continue;
      copyTexels(image, s * (f % 2), s * (f / 2), pages[size_t(t.page)], t.x, t.y, s, s);
      scaleTile(pages[size_t(t.page)], t, s, -t.exponent);
    }
  }
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

Status writeAtlasOutputs(const std::string& dir, const AtlasLayout& packed,
                         const std::vector<RdmData>& rdms) {
  for (const RdmData& d : rdms) {
    for (size_t i = 0; i < d.image.pixels.size(); ++i) {
      if (!std::isfinite(d.image.pixels[i])) {
        return Status::error("non-finite texel in RDM slot (" + std::to_string(d.id.slot.x) + "," +
                             std::to_string(d.id.slot.y) + "," + std::to_string(d.id.slot.z) +
                             ") level " + std::to_string(d.id.level) + "; nothing written");
      }
    }
  }
  if (Status s = makeDirectories(dir); !s) return s;
  const AtlasLayout layout = withTileExponents(packed, rdms);
  const std::vector<std::string> half = layout.radiance == RadianceFormat::kHalf
                                            ? std::vector<std::string>{"R", "G", "B"}
                                            : std::vector<std::string>{};
  std::vector<Image> pages = assembleAtlas(layout, rdms);
  for (size_t p = 0; p < pages.size(); ++p) {
    const std::string path = dir + "/" + atlasPageFileName(int(p));
    if (Status s = writeExr(path, pages[p], kRgbzChannels, half); !s) return s;
  }
  if (Status s = writeFileAtomic(dir + "/index.txt", indexToText(layout)); !s) return s;
  return writeFileAtomic(dir + "/index.json", indexToJson(layout));
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
