#include "noise_map.h"

#include "rdm/exr_io.h"
#include "rdm/lights.h"

namespace rdm::cli {
namespace {

// A copy of `rdm` whose R channel holds the relative standard error.
RdmData noiseOf(const RdmData& rdm) {
  RdmData noise;
  noise.id = rdm.id;
  noise.image = Image(rdm.image.width, rdm.image.height, 4);
  const int s = rdm.id.size;
  for (int y = 0; y < rdm.image.height; ++y) {
    for (int x = 0; x < rdm.image.width; ++x) {
      if (rdm.skipped[size_t((y / s) * 2 + x / s)]) continue;
      const size_t p = size_t(y) * size_t(rdm.image.width) + size_t(x);
      const float* v = &rdm.image.pixels[p * 4];
      const float* e = &rdm.stderr_rgb[p * 3];
      const float value = luminance(glm::vec3(v[0], v[1], v[2]));
      const float error = luminance(glm::vec3(e[0], e[1], e[2]));
      noise.image.pixels[p * 4] = value > 0.0f ? error / value : 0.0f;
    }
  }
  return noise;
}

}  // namespace

std::string noisePageFileName(int page) {
  return page == 0 ? "noise.exr" : "noise.page" + std::to_string(page) + ".exr";
}

Status writeNoiseMaps(const std::string& dir, const AtlasLayout& layout,
                      const std::vector<RdmData>& rdms) {
  std::vector<RdmData> noise;
  noise.reserve(rdms.size());
  for (const RdmData& rdm : rdms) noise.push_back(noiseOf(rdm));
  std::vector<Image> pages = assembleAtlas(layout, noise);
  for (size_t p = 0; p < pages.size(); ++p) {
    Image page(pages[p].width, pages[p].height, 1);
    for (size_t i = 0; i < page.pixels.size(); ++i) page.pixels[i] = pages[p].pixels[i * 4];
    if (Status s = writeExr(dir + "/" + noisePageFileName(int(p)), page, {kNoiseChannel}); !s)
      return s;
  }
  return {};
}

}  // namespace rdm::cli
