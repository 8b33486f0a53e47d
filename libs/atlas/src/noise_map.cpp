#include "rdm/atlas/noise_map.h"

#include "rdm/image/exr_io.h"
#include "rdm/scene/lights.h"

namespace rdm {
namespace {

// The relative standard error of texel (x, y) of `rdm`.
float relativeError(const RdmData& rdm, int x, int y) {
  const size_t p = size_t(y) * size_t(rdm.image.width) + size_t(x);
  const float* v = &rdm.image.pixels[p * 4];
  const float* e = &rdm.stderr_rgb[p * 3];
  const float value = luminance(glm::vec3(v[0], v[1], v[2]));
  const float error = luminance(glm::vec3(e[0], e[1], e[2]));
  return value > 0.0f ? error / value : 0.0f;
}

// Page `page` of the noise map: each stored face tile's relative errors.
Expected<Image> noisePage(const AtlasLayout& layout, int page, const RdmSource& source) {
  const AtlasPage& p = layout.pages.at(size_t(page));
  Image out(p.width, p.height, 1);
  bool measured = true;
  Status s = forEachRdmOnPage(layout, page, source, [&](const AtlasEntry& e, const RdmData& rdm) {
    const int size = e.id.size;
    if (rdm.stderr_rgb.size() != rdm.image.pixels.size() / 4 * 3) {
      measured = false;
      return;
    }
    for (int f = 0; f < 6; ++f) {
      const FaceTile& t = e.faces[size_t(f)];
      if (t.page != page || rdm.skipped[size_t(f)]) continue;
      for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x)
          out.at(t.x + x, t.y + y, 0) = relativeError(rdm, size * (f % 2) + x, size * (f / 2) + y);
    }
  });
  if (!s) return s;
  if (!measured) return Status::invalid("noise", "an RDM's standard error is not stored");
  return out;
}

}  // namespace

std::string noisePageFileName(int page) {
  return page == 0 ? "noise.exr" : "noise.page" + std::to_string(page) + ".exr";
}

Status writeNoiseMaps(const std::string& dir, const AtlasLayout& layout, const RdmSource& source) {
  for (size_t p = 0; p < layout.pages.size(); ++p) {
    auto page = noisePage(layout, int(p), source);
    if (!page) return page.status();
    if (Status s = writeExr(dir + "/" + noisePageFileName(int(p)), *page, {kNoiseChannel}); !s)
      return s;
  }
  return {};
}

}  // namespace rdm
