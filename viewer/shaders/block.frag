#version 450
#extension GL_GOOGLE_include_directive : require
// Real-time RDM shading of docs/spec.md section 6 (thesis 4.3): indirect diffuse and specular from
// the RDM atlas (or docs/spec.md section 7's flat ambient), the direct sun with a soft shadow map, emission.
#include "near_voxels.glsl"

layout(location = 0) in vec3 in_local;
layout(location = 1) flat in ivec4 in_slot;
layout(location = 2) flat in int in_face;
layout(location = 3) flat in vec3 in_center;

layout(location = 0) out vec4 out_color;

// Thesis 4.1.2: the point moves half a voxel against the normal and slightly towards its
// quad's centre, so it lands strictly inside the voxel it belongs to.
uint surfaceVoxel(vec3 n) {
  vec3 q = in_local - 0.5 * n + sign(in_center - in_local) * (1.0 - abs(n)) * 1e-3;
  ivec3 v = clamp(ivec3(floor(q)), ivec3(0), ivec3(kBlockSize - 1));
  return blockVoxel(in_slot.w, v);
}

void main() {
  vec3 n = vec3(faceNormal(in_face));
  SurfaceMaterial s = decodeVoxel(surfaceVoxel(n));
  if (!s.solid) {  // a meshing or lookup bug: make it visible rather than plausible
    out_color = vec4(1.0, 0.0, 1.0, 1.0);
    return;
  }
  vec3 p = vec3(in_slot.xyz) + in_local / float(kBlockSize);
  vec3 v = normalize(frame.camera_position.xyz - p);
  vec3 lr = vec3(0.0);
  if (termOn(kTermSpecular)) {
    vec3 r = reflect(-v, n);
    lr = termOn(kTermRdm) ? specularRadiance(in_slot.xyz, in_face, s.level, p, r) : frame.ambient.rgb;
  }
  vec3 color = surfaceRadiance(s, in_slot.xyz, in_face, in_local / float(kBlockSize), p, n, v, lr);
  out_color = vec4(color, 1.0);
}
