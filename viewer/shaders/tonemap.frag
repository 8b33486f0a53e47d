#version 450
// HDR mean -> Reinhard c / (1 + c) per channel -> sRGB curve (docs/spec.md section 6), into a UNORM target.
layout(set = 0, binding = 0) uniform sampler2D hdr_image;
layout(location = 0) out vec4 out_color;

float srgbEncode(float c) { return c <= 0.0031308 ? 12.92 * c : 1.055 * pow(c, 1.0 / 2.4) - 0.055; }

void main() {
  vec3 c = max(texelFetch(hdr_image, ivec2(gl_FragCoord.xy), 0).rgb, vec3(0.0));
  c = c / (1.0 + c);
  out_color = vec4(srgbEncode(c.r), srgbEncode(c.g), srgbEncode(c.b), 1.0);
}
