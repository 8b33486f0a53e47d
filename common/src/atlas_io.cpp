#include <cmath>
#include <map>
#include <sstream>

#include <nlohmann/json.hpp>

#include "rdm/atlas.h"
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
    const RdmData* data = it->second;
    Image& page = pages[e.page];
    for (int y = 0; y < data->image.height; ++y)
      for (int x = 0; x < data->image.width; ++x)
        for (int c = 0; c < 4; ++c) page.at(e.x + x, e.y + y, c) = data->image.at(x, y, c);
  }
  return pages;
}

std::string indexToJson(const AtlasLayout& layout) {
  json j;
  j["format"] = "rdm-atlas";
  j["version"] = 1;
  j["sky_depth"] = shared::kSkyDepth;
  j["scene_version"] = layout.scene_version;
  j["pages"] = json::array();
  for (const AtlasPage& p : layout.pages)
    j["pages"].push_back({{"width", p.width}, {"height", p.height}});
  j["rdms"] = json::array();
  for (const AtlasEntry& e : layout.entries) {
    j["rdms"].push_back({{"slot", {e.id.slot.x, e.id.slot.y, e.id.slot.z}},
                         {"level", e.id.level},
                         {"size", e.id.size},
                         {"page", e.page},
                         {"rect", {e.x, e.y, 2 * e.id.size, 3 * e.id.size}}});
  }
  return j.dump(1) + "\n";
}

Expected<AtlasLayout> parseIndexJson(const std::string& text) {
  try {
    json j = json::parse(text);
    if (j.at("format") != "rdm-atlas" || j.at("version") != 1)
      return Status::error("index.json: not an rdm-atlas v1 index");
    AtlasLayout layout;
    layout.scene_version = j.value("scene_version", 1LL);
    for (const json& p : j.at("pages"))
      layout.pages.push_back({p.at("width").get<int>(), p.at("height").get<int>()});
    for (const json& r : j.at("rdms")) {
      AtlasEntry e;
      e.id.slot = glm::ivec3(r.at("slot")[0].get<int>(), r.at("slot")[1].get<int>(),
                             r.at("slot")[2].get<int>());
      e.id.level = r.at("level").get<int>();
      e.id.size = r.at("size").get<int>();
      e.page = r.at("page").get<int>();
      e.x = r.at("rect")[0].get<int>();
      e.y = r.at("rect")[1].get<int>();
      if (e.page < 0 || e.page >= int(layout.pages.size()))
        return Status::error("index.json: rdm page out of range");
      layout.entries.push_back(e);
    }
    return layout;
  } catch (const std::exception& e) {
    return Status::error(std::string("index.json: ") + e.what());
  }
}

std::string indexToText(const AtlasLayout& layout) {
  std::ostringstream os;
  int count = 0;
  for (const AtlasEntry& e : layout.entries) count += e.page == 0 ? 1 : 0;
  const AtlasPage page = layout.pages.empty() ? AtlasPage{} : layout.pages[0];
  os << count << " " << page.width << " " << page.height << "\n";
  for (const AtlasEntry& e : layout.entries) {
    if (e.page != 0) continue;
    os << e.id.slot.x << " " << e.id.slot.y << " " << e.id.slot.z << " " << e.id.level << " " << e.x
       << " " << e.y << " " << 2 * e.id.size << " " << 3 * e.id.size << "\n";
  }
  return os.str();
}

std::string atlasPageFileName(int page) {
  return page == 0 ? "atlas.exr" : "atlas.page" + std::to_string(page) + ".exr";
}

Status writeAtlasOutputs(const std::string& dir, const AtlasLayout& layout,
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
  std::vector<Image> pages = assembleAtlas(layout, rdms);
  for (size_t p = 0; p < pages.size(); ++p) {
    if (Status s = writeExr(dir + "/" + atlasPageFileName(int(p)), pages[p], kRgbzChannels); !s)
      return s;
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
