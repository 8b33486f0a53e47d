#include "rdm/image/tonemap.h"

#include <cmath>

namespace rdm {
namespace {

// Clamps to [0, 1]; NaN -> 0.
float clamp01(float v) {
  return v > 0.0f ? (v < 1.0f ? v : 1.0f) : 0.0f;
}

}  // namespace

float srgbEncode(float linear) {
  return linear <= 0.0031308f ? 12.92f * linear : 1.055f * std::pow(linear, 1.0f / 2.4f) - 0.055f;
}

float srgbDecode(float encoded) {
  return encoded <= 0.04045f ? encoded / 12.92f : std::pow((encoded + 0.055f) / 1.055f, 2.4f);
}

Image tonemapReinhardSrgb(const Image& linear) {
  Image out(linear.width, linear.height, linear.channels);
  for (size_t i = 0; i < out.pixels.size(); ++i) {
    float c = linear.pixels[i] > 0.0f ? linear.pixels[i] : 0.0f;  // NaN -> 0
    out.pixels[i] = std::isinf(c) ? 1.0f : clamp01(srgbEncode(c / (1.0f + c)));
  }
  return out;
}

}  // namespace rdm
