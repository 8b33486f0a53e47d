#version 450
// The frame's HDR image into the running mean (viewer/renderer/frame_accumulator.h): the
// pipeline blends out = frame * w + mean * (1 - w) with w as the blend constant. Frames at a
// resolution divisor are scaled up here, nearest (Renderer::setResolutionDivisor).
layout(set = 0, binding = 0) uniform sampler2D hdr_image;
layout(push_constant) uniform Accumulate { int divisor; } accumulate;
layout(location = 0) out vec4 out_color;

void main() {
  out_color = vec4(texelFetch(hdr_image, ivec2(gl_FragCoord.xy) / accumulate.divisor, 0).rgb, 1.0);
}
