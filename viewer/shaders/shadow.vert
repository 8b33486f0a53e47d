#version 450
#extension GL_GOOGLE_include_directive : require
// Depth-only sun shadow map pass over the same block meshes (one draw, scene_gpu.h).
#include "viewer_common.glsl"

layout(location = 0) in uvec2 in_vertex;
layout(location = 1) in ivec4 in_instance;

void main() {
  uint pf = in_vertex.x;
  vec3 local = vec3(float(pf & 255u), float((pf >> 8) & 255u), float((pf >> 16) & 255u));
  vec3 world = vec3(in_instance.xyz) + local / float(kBlockSize);
  gl_Position = frame.light_view_proj * vec4(world, 1.0);
}
