// The cross-block denoiser's filter (docs/denoise.md, rdm/bake/denoise.h), the one
// implementation the CPU (libs/bake/src/denoise.cpp) and Vulkan (shaders/denoise.comp) run:
// which texels it filters, a tap's weight and sums, the parallax that shifts a neighbouring
// block's texel, and the result. Each side walks the window over its own storage, in the same
// order. Float throughout, in the common subset of GLSL 4.50 and C++: the two agree up to the
// device's exp() (a few ulps, tests/vulkan/vulkan_denoise_test.cpp).
#ifndef RDM_DENOISE_H
#define RDM_DENOISE_H

#ifdef __cplusplus
#include "rdm_shared.h"
namespace rdm::shared {
#define RDM_FN inline
#define RDM_CONST constexpr
#define RDM_INOUT(T) T&
#define RDM_IN(T) const T&
#else
#include "rdm_shared.h"
#define RDM_FN
#define RDM_CONST const
#define RDM_INOUT(T) inout T
#define RDM_IN(T) in T
#endif

RDM_CONST float kDenoisePi = 3.14159265358979f;

// A texel as the filter reads it: R, G, B and depth Z; the standard error of R, G, B; and the
// guide variance the colour test uses (the 3 x 3 mean of the squared standard errors around
// it, since an estimate from a few samples is itself noisy). w of error and guide unused.
struct DenoiseTexel {
  vec4 rgbz;
  vec4 error;
  vec4 guide;
};

struct DenoiseParams {
  float inv_spatial;  // 1 / (2 sigma_s^2), sigma_s in texels
  float inv_color;    // 1 / (2 sigma_c^2), sigma_c in units of the pair's standard error
  float depth_sigma;  // relative to the larger depth
  float min_relative_error;
};

struct DenoiseSums {
  float weight;
  vec3 rgb;
  vec3 variance;  // sum of w^2 e^2
};

// Whether a texel's noise calls for the filter: it sees something (Z > 0), carries an error,
// and that error relative to its value (noise.exr's E) is at least the floor.
RDM_FN bool denoiseNeeded(RDM_IN(DenoiseTexel) c, float min_relative_error) {
  float value = lumaRec709(vec3(c.rgbz));
  float error = lumaRec709(vec3(c.error));
  if (!(c.rgbz.w > 0.0f) || error <= 0.0f) return false;
  return value <= 0.0f || error / value >= min_relative_error;
}

// A texel's hemi-oct square spans a quarter turn in S / 2 texels, pi / S radians per texel:
// one unit of origin offset moves a surface at `depth` by this many texels.
RDM_FN float denoiseParallax(int size, float depth) {
  return float(size) / (kDenoisePi * depth);
}

// The nearest of the depths seen so far and `depth` (0: a dead texel, skipped). A texel's
// value mixes the directions around its centre, so the nearest surface sets its parallax.
RDM_FN float denoiseNearer(float nearest, float depth) {
  return depth > 0.0f ? min(nearest, depth) : nearest;
}

// Adds tap `q`, at squared texel distance `d2` from the centre `c` (a neighbouring block's
// parallax included), to `sums`. Dead taps add nothing.
RDM_FN void denoiseAddTap(RDM_INOUT(DenoiseSums) sums, RDM_IN(DenoiseTexel) c,
                          RDM_IN(DenoiseTexel) q, float d2, RDM_IN(DenoiseParams) p) {
  if (!(q.rgbz.w > 0.0f)) return;
  float dz = (q.rgbz.w - c.rgbz.w) / (p.depth_sigma * max(q.rgbz.w, c.rgbz.w));
  vec3 d = vec3(q.rgbz) - vec3(c.rgbz);
  vec3 scale = abs(vec3(q.rgbz)) + abs(vec3(c.rgbz));
  vec3 ratio = d * d / (vec3(c.guide) + vec3(q.guide) + 1e-8f * scale * scale + 1e-30f);
  float color2 = (ratio.x + ratio.y + ratio.z) / 3.0f;
  float w = exp(-d2 * p.inv_spatial - 0.5f * dz * dz - color2 * p.inv_color);
  sums.weight += w;
  sums.rgb += w * vec3(q.rgbz);
  sums.variance += (w * w) * (vec3(q.error) * vec3(q.error));
}

// The filtered texel: the weighted mean, its standard error, the centre's depth.
RDM_FN DenoiseTexel denoiseResult(RDM_IN(DenoiseSums) sums, RDM_IN(DenoiseTexel) c) {
  DenoiseTexel result = c;
  result.rgbz = vec4(sums.rgb / sums.weight, c.rgbz.w);
  result.error = vec4(sqrt(sums.variance) / sums.weight, 0.0f);
  return result;
}

#ifdef __cplusplus
}  // namespace rdm::shared
#endif
#undef RDM_FN
#undef RDM_CONST
#undef RDM_INOUT
#undef RDM_IN
#endif  // RDM_DENOISE_H
