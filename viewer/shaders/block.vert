#version 450
#extension GL_GOOGLE_include_directive : require
// Greedy-meshed blocks, every slot's copy in one draw: the vertex holds its position in slot
// voxel units and its slot and oriented block (viewer/renderer/mesher.h, scene_gpu.h).
#include "viewer_common.glsl"

layout(location = 0) in uvec2 in_vertex;    // position | face << 24, 2 * quad centre
layout(location = 1) in ivec4 in_instance;  // slot xyz, oriented block index (per vertex)

layout(location = 0) out vec3 out_local;         // slot voxel units, 0..16
layout(location = 1) flat out ivec4 out_slot;    // slot xyz, oriented block
layout(location = 2) flat out int out_face;      // docs/spec.md face index of the normal
layout(location = 3) flat out vec3 out_center;   // quad centre, slot voxel units

invariant gl_Position;  // the depth pre-pass and the shading pass must agree to the bit

void main() {
  uint pf = in_vertex.x, c2 = in_vertex.y;
  vec3 local = vec3(float(pf & 255u), float((pf >> 8) & 255u), float((pf >> 16) & 255u));
  out_local = local;
  out_slot = in_instance;
  out_face = int(pf >> 24);
  out_center = 0.5 * vec3(float(c2 & 255u), float((c2 >> 8) & 255u), float((c2 >> 16) & 255u));
  vec3 world = vec3(in_instance.xyz) + local / float(kBlockSize);
  gl_Position = frame.view_proj * vec4(world, 1.0);
}
