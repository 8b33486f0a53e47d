#include "rdm/atlas/atlas_delta.h"

#include <cstring>

#include <nlohmann/json.hpp>

#include "rdm/atlas/atlas_json.h"

#include "rdm/bake/preview_pass.h"
#include "rdm/scene/bake_settings_json.h"

namespace rdm {
namespace {

using nlohmann::json;

constexpr char kMagic[8] = {'R', 'D', 'M', 'D', 'L', 'T', '0', '2'};
constexpr uint32_t kMaxHeader = 64u << 20;

// Floats of a rect on the wire: its stored faces, s x s RGBZ texels each.
size_t rectFloats(const AtlasEntry& e, int texel_size) {
  return size_t(__builtin_popcount(e.storedMask())) * size_t(texel_size) * size_t(texel_size) * 4;
}

// Appends the stored faces of a 2s x 3s image, face by face, each row-major.
void appendFaces(const AtlasEntry& e, const Image& texels, std::string& out) {
  const int s = texels.width / 2;
  for (int f = 0; f < 6; ++f) {
    if (!e.faces[size_t(f)].stored()) continue;
    for (int y = 0; y < s; ++y) {
      const float* row = &texels.pixels[(size_t(s * (f / 2) + y) * texels.width + s * (f % 2)) * 4];
      out.append(reinterpret_cast<const char*>(row), size_t(s) * 4 * sizeof(float));
    }
  }
}

// The inverse of appendFaces: a 2s x 3s image, unstored faces 0.
Image readFaces(const AtlasEntry& e, int s, const char*& at) {
  Image texels(2 * s, 3 * s, 4);
  for (int f = 0; f < 6; ++f) {
    if (!e.faces[size_t(f)].stored()) continue;
    for (int y = 0; y < s; ++y) {
      float* row = &texels.pixels[(size_t(s * (f / 2) + y) * texels.width + s * (f % 2)) * 4];
      std::memcpy(row, at, size_t(s) * 4 * sizeof(float));
      at += size_t(s) * 4 * sizeof(float);
    }
  }
  return texels;
}

Status invalid(const std::string& part, const std::string& what) {
  return Status::invalid(part, "atlas delta: " + part + ": " + what);
}

}  // namespace

RdmKey rdmKey(const RdmId& id) {
  return {id.slot.x, id.slot.y, id.slot.z, id.level};
}

bool samePages(const AtlasLayout& a, const AtlasLayout& b) {
  if (a.pages.size() != b.pages.size()) return false;
  for (size_t i = 0; i < a.pages.size(); ++i) {
    if (a.pages[i].width != b.pages[i].width || a.pages[i].height != b.pages[i].height)
      return false;
  }
  return true;
}

bool pagesGrow(const AtlasLayout& old, const AtlasLayout& now) {
  if (old.pages.size() > now.pages.size()) return false;
  for (size_t i = 0; i < old.pages.size(); ++i) {
    if (old.pages[i].width > now.pages[i].width || old.pages[i].height > now.pages[i].height)
      return false;
  }
  return true;
}

DeltaSelection selectDelta(const AtlasView& old, const AtlasView& now) {
  std::map<RdmKey, const AtlasEntry*> old_entries;
  for (const AtlasEntry& e : old.layout.entries) old_entries[rdmKey(e.id)] = &e;
  auto originOf = [](const AtlasView& v, const RdmKey& k) {
    auto it = v.origin.find(k);
    return it == v.origin.end() ? std::string() : it->second;
  };
  DeltaSelection out;
  for (const AtlasEntry& e : now.layout.entries) {
    const RdmKey key = rdmKey(e.id);
    auto it = old_entries.find(key);
    if (it == old_entries.end()) {
      out.rects.push_back(e);
      continue;
    }
    const AtlasEntry& o = *it->second;
    if (o.id.size != e.id.size || o.faces != e.faces || originOf(old, key) != originOf(now, key) ||
        originOf(now, key).empty())
      out.rects.push_back(e);
    old_entries.erase(it);
  }
  for (const auto& [key, e] : old_entries) out.removed.push_back(*e);
  return out;
}

std::string encodeAtlasDelta(const AtlasDelta& d) {
  json rects = json::array(), removed = json::array();
  for (const DeltaRect& r : d.rects) {
    json j = atlasEntryJson(r.entry);
    j["texel_size"] = r.texels.width / 2;
    rects.push_back(std::move(j));
  }
  for (const AtlasEntry& e : d.removed) removed.push_back(atlasEntryJson(e));
  const json header = {{"job", d.job},
                       {"from", d.from},
                       {"pass", d.pass},
                       {"passes", d.passes},
                       {"final", d.final},
                       {"settings", bakeSettingsToJson(d.settings)},
                       {"index", json::parse(indexToJson(d.layout))},
                       {"rects", rects},
                       {"removed", removed}};
  const std::string text = header.dump();
  std::string out(kMagic, sizeof(kMagic));
  const uint32_t length = uint32_t(text.size());
  out.append(reinterpret_cast<const char*>(&length), sizeof(length));
  out += text;
  size_t floats = 0;
  for (const DeltaRect& r : d.rects) floats += rectFloats(r.entry, r.texels.width / 2);
  out.reserve(out.size() + floats * sizeof(float));
  for (const DeltaRect& r : d.rects) {
    const int s = r.texels.width / 2;
    RDM_CHECK(s >= 1 && s <= r.entry.id.size && r.texels.width == 2 * s &&
              r.texels.height == 3 * s && r.texels.channels == 4);
    appendFaces(r.entry, r.texels, out);
  }
  return out;
}

Expected<AtlasDelta> decodeAtlasDelta(const std::string& bytes) {
  if (bytes.size() < sizeof(kMagic) + 4 || std::memcmp(bytes.data(), kMagic, sizeof(kMagic)) != 0)
    return invalid("magic", "not an RDMDLT02 message");
  uint32_t length = 0;
  std::memcpy(&length, bytes.data() + sizeof(kMagic), sizeof(length));
  const size_t start = sizeof(kMagic) + sizeof(length);
  if (length > kMaxHeader || length > bytes.size() - start)
    return invalid("header", "length " + std::to_string(length) + " past the end");
  AtlasDelta d;
  size_t need = 0;
  std::vector<int> texel_sizes;
  try {
    const json h = json::parse(bytes.substr(start, length));
    d.job = h.at("job"), d.from = h.at("from");
    d.pass = h.at("pass"), d.passes = h.at("passes"), d.final = h.at("final");
    auto settings = readBakeSettings(h.at("settings"), {"settings", {}, BakeSettingsForm::kRecord});
    if (!settings) {
      return Status::invalid(settings.status().field(), "atlas delta: " + settings.error());
    }
    d.settings = *settings;
    auto layout = parseIndexJson(h.at("index").dump());
    if (!layout) return invalid("index", layout.error());
    d.layout = std::move(*layout);
    for (const json& r : h.at("rects")) {
      const AtlasEntry e = atlasEntryOf(r);
      texel_sizes.push_back(r.contains("texel_size") ? r.at("texel_size").get<int>() : e.id.size);
      d.rects.push_back({e, Image()});
    }
    for (const json& r : h.at("removed")) d.removed.push_back(atlasEntryOf(r));
  } catch (const std::exception&) {
    return invalid("header", "malformed JSON or a missing or mistyped field");
  }
  for (size_t i = 0; i < d.rects.size(); ++i) {
    if (!tilesFit(d.rects[i].entry, d.layout.pages))
      return invalid("rects[" + std::to_string(i) + "]", "outside the atlas pages");
    if (texel_sizes[i] < 1 || texel_sizes[i] > d.rects[i].entry.id.size)
      return invalid("rects[" + std::to_string(i) + "].texel_size",
                     std::to_string(texel_sizes[i]) + " is not in 1.." +
                         std::to_string(d.rects[i].entry.id.size));
    need += rectFloats(d.rects[i].entry, texel_sizes[i]) * sizeof(float);
  }
  if (bytes.size() - start - length != need)
    return invalid("texels", std::to_string(bytes.size() - start - length) + " bytes, expected " +
                                 std::to_string(need));
  const char* at = bytes.data() + start + length;
  for (size_t i = 0; i < d.rects.size(); ++i) {
    DeltaRect& r = d.rects[i];
    r.texels = expandRdmImage(readFaces(r.entry, texel_sizes[i], at), r.entry.id.size);
  }
  return d;
}

}  // namespace rdm
