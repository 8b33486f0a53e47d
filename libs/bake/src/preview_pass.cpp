#include "rdm/bake/preview_pass.h"

#include <algorithm>

#include "rdm/base/check.h"
#include "rdm/transport/rdm_shared_cpp.h"

namespace rdm {

std::vector<BakeSettings> progressivePasses(const BakeSettings& settings) {
  BakeSettings preview = settings;
  preview.spp = std::max(1, settings.spp / kPreviewDivisor);
  preview.max_bounces = std::min(settings.max_bounces, kPreviewBounces);
  preview.estimator = Estimator::kNaive;
  preview.max_hemisphere = std::max(2, settings.max_hemisphere / 2);
  if (preview.spp * 4 > settings.spp) return {settings};
  return {preview, settings};
}

std::vector<RdmId> atPassSizes(const std::vector<RdmId>& plan, const BakeSettings& pass) {
  std::vector<RdmId> out = plan;
  for (RdmId& id : out) id.size = shared::hemisphereSize(id.level, pass.max_hemisphere);
  return out;
}

Image expandRdmImage(const Image& image, int size) {
  const int s = image.width / 2;
  RDM_CHECK(image.width == 2 * s && image.height == 3 * s && s >= 1 && size >= s);
  if (size == s) return image;
  Image out(2 * size, 3 * size, image.channels);
  for (int f = 0; f < 6; ++f)
    for (int j = 0; j < size; ++j)
      for (int i = 0; i < size; ++i) {
        const int x = size * (f % 2) + i, y = size * (f / 2) + j;
        const int sx = s * (f % 2) + i * s / size, sy = s * (f / 2) + j * s / size;
        for (int c = 0; c < image.channels; ++c) out.at(x, y, c) = image.at(sx, sy, c);
      }
  return out;
}

}  // namespace rdm
