// Float images with the docs/spec.md section 4 convention: origin top-left, x right, y down,
// row-major, interleaved channels.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

#include "rdm/base/check.h"

namespace rdm {

struct Image {
  int width = 0;
  int height = 0;
  int channels = 0;
  std::vector<float> pixels;  // size width * height * channels

  Image() = default;
  Image(int w, int h, int c) : width(w), height(h), channels(c), pixels(size_t(w) * h * c, 0.0f) {}

  float& at(int x, int y, int c) {
    RDM_CHECK(x >= 0 && x < width && y >= 0 && y < height && c >= 0 && c < channels);
    return pixels[(size_t(y) * width + x) * channels + c];
  }
  float at(int x, int y, int c) const {
    RDM_CHECK(x >= 0 && x < width && y >= 0 && y < height && c >= 0 && c < channels);
    return pixels[(size_t(y) * width + x) * channels + c];
  }
};

// Copies the width x height texels at (sx, sy) of `src` to (dx, dy) of `dst`; both images have
// the same channel count and both rects lie inside their images.
inline void copyTexels(const Image& src, int sx, int sy, Image& dst, int dx, int dy, int width,
                       int height) {
  RDM_CHECK(src.channels == dst.channels && sx >= 0 && sy >= 0 && dx >= 0 && dy >= 0);
  RDM_CHECK(sx + width <= src.width && sy + height <= src.height);
  RDM_CHECK(dx + width <= dst.width && dy + height <= dst.height);
  const size_t row = size_t(width) * size_t(src.channels) * sizeof(float);
  for (int y = 0; y < height; ++y)
    std::memcpy(&dst.pixels[(size_t(dy + y) * dst.width + size_t(dx)) * dst.channels],
                &src.pixels[(size_t(sy + y) * src.width + size_t(sx)) * src.channels], row);
}

// 8-bit raster, row-major, top-left origin, `channels` interleaved bytes per pixel.
struct Image8 {
  int width = 0;
  int height = 0;
  int channels = 0;
  std::vector<uint8_t> pixels;
};

}  // namespace rdm
