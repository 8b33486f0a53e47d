// Reading an atlas back (rdm/atlas/atlas.h): the pages of an output directory, one RDM's tiles, and
// the comparison of two atlases RDM by RDM whatever their layouts.
#include <cstring>
#include <map>
#include <tuple>

#include "rdm/atlas/atlas.h"
#include "rdm/base/file_util.h"
#include "rdm/image/exr_io.h"

namespace rdm {

Expected<AtlasLayout> readAtlasLayout(const std::string& dir) {
  auto text = readFileToString(dir + "/index.json");
  if (!text) return Status::error(StatusCode::kIo, "cannot read " + dir + "/index.json");
  auto layout = parseIndexJson(*text);
  if (!layout) return Status::invalid("index.json", dir + "/" + layout.error());
  return layout;
}

namespace {

// Page `page` of `dir` as stored (R, G, B, Z; tile exponents not undone), its size checked.
Expected<Image> readStoredPage(const std::string& dir, const AtlasLayout& layout, int page) {
  if (layout.radiance == RadianceFormat::kBc6h) return readBc6hAtlasPage(dir, layout, page);
  const std::string path = dir + "/" + atlasPageFileName(page);
  auto texels = readExr(path, kRgbzChannels);
  if (!texels) return texels.status();
  const AtlasPage& size = layout.pages[size_t(page)];
  if (texels->width != size.width || texels->height != size.height)
    return Status::invalid("index.json", path + ": size differs from index.json");
  return texels;
}

}  // namespace

Expected<LoadedAtlas> readAtlasOutputs(const std::string& dir) {
  auto layout = readAtlasLayout(dir);
  if (!layout) return layout.status();
  LoadedAtlas atlas;
  atlas.layout = std::move(*layout);
  for (size_t p = 0; p < atlas.layout.pages.size(); ++p) {
    auto page = readStoredPage(dir, atlas.layout, int(p));
    if (!page) return page.status();
    restoreRadiance(atlas.layout, int(p), *page);
    atlas.pages.push_back(std::move(*page));
  }
  return atlas;
}

Image rdmTexels(const LoadedAtlas& atlas, const AtlasEntry& e) {
  const int size = e.id.size;
  Image out(2 * size, 3 * size, 4);
  for (int f = 0; f < 6; ++f) {
    const FaceTile& t = e.faces[size_t(f)];
    if (!t.stored()) continue;
    copyTexels(atlas.pages[size_t(t.page)], t.x, t.y, out, size * (f % 2), size * (f / 2), size,
               size);
  }
  return out;
}

Image faceTexels(const Image& rdm_image, int face) {
  const int size = rdm_image.width / 2;
  Image out(size, size, rdm_image.channels);
  copyTexels(rdm_image, size * (face % 2), size * (face / 2), out, 0, 0, size, size);
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
        it->second->storedMask() == e.storedMask() &&
        std::memcmp(rdmTexels(a, e).pixels.data(), rdmTexels(b, *it->second).pixels.data(),
                    size_t(4 * e.id.size) * size_t(6 * e.id.size) * sizeof(float)) == 0;
    if (!same) out.push_back(e.id);
    if (it != in_b.end()) in_b.erase(it);
  }
  for (const auto& [key, e] : in_b) out.push_back(e->id);
  return out;
}

}  // namespace rdm
