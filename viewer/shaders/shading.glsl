// Material, BSDF and light terms of docs/spec.md sections 5 and 6 for the block fragment shader.
#ifndef VIEWER_SHADING_GLSL
#define VIEWER_SHADING_GLSL

#include "viewer_common.glsl"

const int kDfgColumns = 64;  // viewer/renderer/shading_tables.h

// Oriented blocks' voxels in slot space, one [r, g, b, m] word each (byte 0 = r): the
// thesis's RGBA8 material texture, 4096 words per block, index x + 16 y + 256 z.
layout(set = 0, binding = 1) uniform usamplerBuffer voxel_data;

// The word of voxel `local` of oriented block `block`.
uint blockVoxel(int block, ivec3 local) {
  return texelFetch(voxel_data, block * kBlockVoxelCount + local.x + kBlockSize * local.y +
                                    kBlockSize * kBlockSize * local.z).r;
}

// The mask of oriented block `block`'s non-empty 4^3 bricks (brick bx | by << 2 | bz << 4),
// low 32 bricks in x; the masks follow the voxel words (viewer/renderer/scene_gpu.h).
uvec2 blockBricks(int block) {
  int base = (textureSize(voxel_data) / (kBlockVoxelCount + 2)) * kBlockVoxelCount + 2 * block;
  return uvec2(texelFetch(voxel_data, base).r, texelFetch(voxel_data, base + 1).r);
}

// Split-sum DFG (A, B) and the diffuse albedo factor C per (level, mu column); the sRGB
// decoding table of the core (rdm::srgbToLinear) for the voxel colour bytes.
layout(std430, set = 0, binding = 3) readonly buffer Tables {
  vec4 dfg[kLevelCount * kDfgColumns];
  float srgb_to_linear[256];
};

struct SurfaceMaterial {
  vec3 color;     // linear base colour c
  vec3 f0;        // (1 - m) 0.04 + m c
  vec3 emission;  // radiance
  float metallic;
  float alpha;    // GGX (r/7)^2
  int level;      // roughness level r
  bool solid;
};

SurfaceMaterial decodeVoxel(uint word) {
  SurfaceMaterial s;
  uint m = word >> 24;
  s.solid = materialSolid(m);
  s.color = vec3(srgb_to_linear[word & 255u], srgb_to_linear[(word >> 8) & 255u],
                 srgb_to_linear[(word >> 16) & 255u]);
  s.metallic = metallicFactor(materialMetallic(m));
  s.level = materialRoughness(m);
  s.alpha = roughnessAlpha(s.level);
  s.f0 = materialF0(s.color, s.metallic);
  s.emission = s.color * (float(materialEmission(m)) / 3.0 * frame.ambient.w);
  return s;
}

// (A, B, C) at roughness level `level` and mu = n.v, linear in mu, clamped.
vec3 dfgLookup(int level, float mu) {
  float x = clamp(mu * float(kDfgColumns) - 0.5, 0.0, float(kDfgColumns - 1));
  int c0 = int(x);
  int c1 = min(c0 + 1, kDfgColumns - 1);
  return mix(dfg[level * kDfgColumns + c0], dfg[level * kDfgColumns + c1], x - float(c0)).xyz;
}

// Direct sun, docs/spec.md section 6: Lambert weighted by 1 - F plus GGX with alpha' = max(alpha, sin theta);
// F, D and V are the core's (rdm_shared.h).
vec3 sunBsdfCos(SurfaceMaterial s, vec3 n, vec3 v, vec3 l) {
  float n_dot_l = dot(n, l);
  if (n_dot_l <= 0.0) return vec3(0.0);
  float n_dot_v = max(dot(n, v), 1e-4);
  vec3 h = normalize(v + l);
  vec3 f = bsdfFresnel(s.f0, clamp(dot(v, h), 0.0, 1.0));
  float alpha = max(s.alpha, frame.sun_irradiance.w);
  vec3 diffuse = (1.0 - s.metallic) * (vec3(1.0) - f) * s.color / kPiF;
  vec3 specular = bsdfGgxD(max(dot(n, h), 0.0), alpha) * bsdfVisibility(n_dot_v, n_dot_l, alpha) * f;
  return (diffuse + specular) * n_dot_l;
}

#endif  // VIEWER_SHADING_GLSL
