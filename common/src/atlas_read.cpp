// Reading an atlas back (rdm/atlas.h): the pages of an output directory, one RDM's rect, and
// the comparison of two atlases RDM by RDM whatever their layouts.
#include <cstring>
#include <map>
#include <tuple>

#include "rdm/atlas.h"
#include "rdm/exr_io.h"
#include "rdm/file_util.h"

namespace rdm {

Expected<LoadedAtlas> readAtlasOutputs(const std::string& dir) {
  auto text = readFileToString(dir + "/index.json");
  if (!text) return Status::error(StatusCode::kIo, "cannot read " + dir + "/index.json");
  auto layout = parseIndexJson(*text);
  if (!layout) return Status::invalid("index.json", dir + "/index.json: " + layout.error());
  LoadedAtlas atlas;
  atlas.layout = std::move(*layout);
  for (size_t p = 0; p < atlas.layout.pages.size(); ++p) {
    const std::string path = dir + "/" + atlasPageFileName(int(p));
    auto page = readExr(path, kRgbzChannels);
    if (!page) return page.status();
    if (page->width != atlas.layout.pages[p].width ||
        page->height != atlas.layout.pages[p].height) {
      return Status::invalid("index.json", path + ": size differs from index.json");
    }
    atlas.pages.push_back(std::move(*page));
  }
  return atlas;
}

Image rdmTexels(const LoadedAtlas& atlas, const AtlasEntry& e) {
  const Image& page = atlas.pages[size_t(e.page)];
  Image out(2 * e.id.size, 3 * e.id.size, 4);
  for (int y = 0; y < out.height; ++y)
    std::memcpy(&out.pixels[size_t(y) * out.width * 4],
                &page.pixels[(size_t(e.y + y) * page.width + size_t(e.x)) * 4],
                size_t(out.width) * 4 * sizeof(float));
  return out;
}

std::vector<RdmId> differingRdms(const LoadedAtlas& a, const LoadedAtlas& b) {
  using Key = std::tuple<int, int, int, int>;
  auto keyOf = [](const RdmId& id) { return Key{id.slot.x, id.slot.y, id.slot.z, id.level}; };
  std::map<Key, const AtlasEntry*> in_b;
  for (const AtlasEntry& e : b.layout.entries) in_b[keyOf(e.id)] = &e;
  std::vector<RdmId> out;
  for (const AtlasEntry& e : a.layout.entries) {
    auto it = in_b.find(keyOf(e.id));
    const bool same =
        it != in_b.end() && it->second->id.size == e.id.size &&
        std::memcmp(rdmTexels(a, e).pixels.data(), rdmTexels(b, *it->second).pixels.data(),
                    size_t(4 * e.id.size) * size_t(6 * e.id.size) * sizeof(float)) == 0;
    if (!same) out.push_back(e.id);
    if (it != in_b.end()) in_b.erase(it);
  }
  for (const auto& [key, e] : in_b) out.push_back(e->id);
  return out;
}

}  // namespace rdm
