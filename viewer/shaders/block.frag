#version 450
#extension GL_GOOGLE_include_directive : require
// Real-time RDM shading of docs/spec.md section 6 (thesis 4.3): indirect diffuse and specular from
// the RDM atlas (or docs/spec.md section 7's flat ambient), the direct sun with a soft shadow map, emission.
#include "shading.glsl"
#include "rdm_lookup.glsl"

layout(set = 0, binding = 5) uniform sampler2DShadow shadow_map;

layout(location = 0) in vec3 in_local;
layout(location = 1) flat in ivec4 in_slot;
layout(location = 2) flat in int in_face;
layout(location = 3) flat in vec3 in_center;

layout(location = 0) out vec4 out_color;

// Gaussian-weighted PCF: 5 x 5 hardware-compared bilinear taps, sigma = 1.25 texels.
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

// Thesis 4.1.2: the point moves half a voxel against the normal and slightly towards its
// quad's centre, so it lands strictly inside the voxel it belongs to.
uint surfaceVoxel(vec3 n) {
  vec3 q = in_local - 0.5 * n + sign(in_center - in_local) * (1.0 - abs(n)) * 1e-3;
  ivec3 v = clamp(ivec3(floor(q)), ivec3(0), ivec3(kBlockSize - 1));
  return texelFetch(voxel_data, in_slot.w * kBlockVoxelCount + v.x + kBlockSize * v.y + kBlockSize * kBlockSize * v.z).r;
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
  float n_dot_v = max(dot(n, v), 1e-4);
  vec3 abc = dfgLookup(s.level, n_dot_v);
  bool rdm = termOn(kTermRdm);
  vec3 color = vec3(0.0);
  if (termOn(kTermDiffuse)) {
    vec3 l7 = rdm ? rdmDiffuse(in_slot.xyz, in_face, in_local / float(kBlockSize)) : frame.ambient.rgb;
    color += (1.0 - s.metallic) * (vec3(1.0) - s.f0) * abc.z * s.color * l7;
  }
  if (termOn(kTermSpecular)) {
    vec3 r = reflect(-v, n);
    vec3 lr = rdm ? rdmSpecular(in_slot.xyz, in_face, s.level, p, r) : frame.ambient.rgb;
    color += lr * (s.f0 * abc.x + abc.y);
  }
  if (termOn(kTermSun) && frame.sun_direction.w > 0.0) {
    vec3 l = frame.sun_direction.xyz;
    float vis = (termOn(kTermShadows) && dot(n, l) > 0.0) ? sunVisibility(p, n) : 1.0;
    color += sunBsdfCos(s, n, v, l) * frame.sun_irradiance.rgb * vis;
  }
  if (termOn(kTermEmission)) color += s.emission;
  out_color = vec4(color, 1.0);
}
