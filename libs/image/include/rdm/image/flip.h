// FLIP image difference (Andersson et al., HPG 2020: LDR-FLIP; EG 2021: HDR-FLIP), as in
// notes/formulas.md section 4.7, and a magma error-map visualisation with a colour legend.
// The tone mapping images are compared after is rdm/image/tonemap.h.
#pragma once

#include <cstdint>
#include <vector>

#include "rdm/image/image.h"

namespace rdm {

// 0.7 m wide 4K monitor viewed from 0.7 m: 3840 / 0.7 * 0.7 * pi / 180.
inline constexpr double kDefaultPixelsPerDegree = 67.02;

struct FlipResult {
  Image error_map;  // same size as the inputs, 1 channel, per-pixel FLIP in [0, 1]
  double mean = 0;  // mean of error_map
};

// LDR-FLIP of two 3-channel images holding sRGB-encoded values; values outside [0, 1] are
// clamped (NaN counts as 0). The images must have the same size (RDM_CHECK).
FlipResult computeLdrFlip(const Image& reference_srgb, const Image& test_srgb,
                          double pixels_per_degree = kDefaultPixelsPerDegree);

// HDR-FLIP of two 3-channel linear-radiance images: LDR-FLIP after the ACES-fit tone
// mapper at exposures spanning the reference's luminance range (max(2, ceil(stop - start))
// of them), per-pixel maximum over exposures. Negative and NaN values count as 0. Luminances
// below 1e-6 count as 1e-6 when choosing the exposures (so a mostly black reference gets
// up to ~20 extra exposures); an all-black reference uses exposure 0 only. Same size
// required (RDM_CHECK).
FlipResult computeHdrFlip(const Image& reference_linear, const Image& test_linear,
                          double pixels_per_degree = kDefaultPixelsPerDegree);

// Magma colour map of a 1-channel image with values in [0, 1] (clamped); 3 channels.
Image8 magmaColorMap(const Image& error_map);

// `map` (3 channels) with a legend appended below it: a magma gradient strip from 0 (left)
// to 1 (right) with tick marks and labels at 0, 0.25, 0.5, 0.75 and 1.
Image8 appendColorLegend(const Image8& map);

}  // namespace rdm
