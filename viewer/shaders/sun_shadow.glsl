// Shadow-mapped visibility of the sun for the block fragment shader (docs/spec.md section 6).
#ifndef VIEWER_SUN_SHADOW_GLSL
#define VIEWER_SUN_SHADOW_GLSL

#include "viewer_common.glsl"

layout(set = 0, binding = 5) uniform sampler2DShadow shadow_map;

// Gaussian-weighted PCF: 5 x 5 hardware-compared bilinear taps, sigma = 1.25 texels.
// p: world point (block units), n: its surface normal.
float sunVisibility(vec3 p, vec3 n) {
  float texel = frame.viewport.z;
  vec4 c = frame.light_view_proj * vec4(p + n * (1.5 * texel), 1.0);
  vec3 s = c.xyz / c.w;
  vec2 uv = s.xy * 0.5 + 0.5;
  if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0))) || s.z >= 1.0) return 1.0;
  vec2 size = vec2(textureSize(shadow_map, 0));
  float sum = 0.0, weight_sum = 0.0;
  for (int y = -2; y <= 2; ++y) {
    for (int x = -2; x <= 2; ++x) {
      float w = exp(-float(x * x + y * y) / (2.0 * 1.25 * 1.25));
      sum += w * texture(shadow_map, vec3(uv + vec2(x, y) / size, s.z - 2e-4));
      weight_sum += w;
    }
  }
  return sum / weight_sum;
}

#endif  // VIEWER_SUN_SHADOW_GLSL
