// The tone mapping images are compared and shown after (docs/spec.md section 6): Reinhard
// c / (1 + c) per channel, then the sRGB curve. `rdm flip`, `rdm render`, `rdm preview` and the
// viewer's tonemap pass agree on it.
#pragma once

#include "rdm/image/image.h"

namespace rdm {

// sRGB transfer curve on one value; srgbEncode takes linear, srgbDecode returns linear.
// Neither clamps.
float srgbEncode(float linear);
float srgbDecode(float encoded);

// Per channel c / (1 + c) (c clamped to >= 0, +inf maps to 1), then srgbEncode. Any
// channel count; the result is in [0, 1].
Image tonemapReinhardSrgb(const Image& linear);

}  // namespace rdm
