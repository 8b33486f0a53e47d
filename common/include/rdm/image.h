// Float images with the docs/spec.md section 4 convention: origin top-left, x right, y down,
// row-major, interleaved channels.
#pragma once

#include <cstddef>
#include <vector>

#include "rdm/check.h"

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

}  // namespace rdm
