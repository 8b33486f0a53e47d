#version 450
#extension GL_GOOGLE_include_directive : require
// Background: the docs/spec.md section 2 sky gradient plus the sun disc, along docs/spec.md section 4's camera rays.
#include "viewer_common.glsl"

layout(location = 0) out vec4 out_color;

void main() {
  if (!termOn(kTermBackground)) {
    out_color = vec4(0.0, 0.0, 0.0, 1.0);
    return;
  }
  vec2 pixel = gl_FragCoord.xy + frame.jitter.xy;  // (x + 0.5, y + 0.5) + the frame's jitter
  float a = (2.0 * pixel.x / frame.viewport.x - 1.0) * frame.camera_position.w * frame.camera_forward.w;
  float b = (1.0 - 2.0 * pixel.y / frame.viewport.y) * frame.camera_position.w;
  vec3 d = normalize(frame.camera_forward.xyz + a * frame.camera_right.xyz + b * frame.camera_up.xyz);
  vec3 color = skyRadiance(d);
  vec3 e = d - frame.sun_direction.xyz;
  if (frame.sun_direction.w > 0.0 && dot(e, e) <= frame.sun_radiance.w) color += frame.sun_radiance.rgb;
  out_color = vec4(color, 1.0);
}
