// Conventions shared by the C++ core, the Vulkan bake kernels and the viewer shaders
// (SPEC sections 1, 3 and 5). Written in the common subset of GLSL 4.50 and C++ with GLM,
// so every convention is defined exactly once.
#ifndef RDM_SHARED_H
#define RDM_SHARED_H

#ifdef __cplusplus
#include <cstdint>
#include <glm/glm.hpp>
namespace rdm::shared {
using namespace glm;
using uint = std::uint32_t;
#define RDM_FN inline
#define RDM_CONST constexpr
#define RDM_INOUT(T) T&
#else
#define RDM_FN
#define RDM_CONST const
#define RDM_INOUT(T) inout T
#endif

RDM_CONST int kBlockSize = 16;           // voxels per block edge
RDM_CONST int kBlockVoxelCount = 4096;   // 16^3, voxel index x + 16 y + 256 z
RDM_CONST int kFaceCount = 6;            // 0 +X, 1 -X, 2 +Y, 3 -Y, 4 +Z, 5 -Z
RDM_CONST int kLevelCount = 8;           // roughness levels 0..7; level 7 is diffuse
RDM_CONST int kDiffuseLevel = 7;
RDM_CONST float kSkyDepth = 1.0e4;       // depth stored for a miss, world units
RDM_CONST int kOrientationCount = 24;

// Material byte m of a voxel [r, g, b, m] (SPEC section 1).
RDM_CONST uint kSolidBit = 0x80u;
RDM_FN bool materialSolid(uint m) { return (m & kSolidBit) != 0u; }
RDM_FN int materialRoughness(uint m) { return int(m & 7u); }
RDM_FN int materialMetallic(uint m) { return int((m >> 3) & 3u); }
RDM_FN int materialEmission(uint m) { return int((m >> 5) & 3u); }
RDM_FN uint packMaterial(int roughness, int metallic, int emission) {
  return kSolidBit | uint(roughness) | (uint(metallic) << 3) | (uint(emission) << 5);
}
// GGX alpha of roughness level r: (r/7)^2.
RDM_FN float roughnessAlpha(int level) {
  float r = float(level) / 7.0f;
  return r * r;
}

// Face frames (t, b, n), right-handed, SPEC section 3.
RDM_FN ivec3 faceNormal(int f) {
  int s = (f % 2 == 0) ? 1 : -1;
  return f < 2 ? ivec3(s, 0, 0) : (f < 4 ? ivec3(0, s, 0) : ivec3(0, 0, s));
}
RDM_FN ivec3 faceTangent(int f) {
  if (f == 0) return ivec3(0, 0, -1);
  if (f == 1) return ivec3(0, 0, 1);
  if (f == 5) return ivec3(-1, 0, 0);
  return ivec3(1, 0, 0);
}
RDM_FN ivec3 faceBitangent(int f) {
  if (f == 2) return ivec3(0, 0, -1);
  if (f == 3) return ivec3(0, 0, 1);
  return ivec3(0, 1, 0);
}

// Hemi-oct encoding of a local direction (d.z along the face normal). Directions below
// the horizon are clamped onto it first; the result lies in [-1, 1]^2.
RDM_FN vec2 hemiOctEncode(vec3 d) {
  d.z = max(d.z, 0.0f);
  float norm = abs(d.x) + abs(d.y) + d.z;
  if (!(norm > 0.0f)) return vec2(0.0f, 0.0f);
  vec2 p = vec2(d.x, d.y) / norm;
  return vec2(p.x + p.y, p.x - p.y);
}
RDM_FN vec3 hemiOctDecode(vec2 e) {
  vec2 p = vec2(e.x + e.y, e.x - e.y) * 0.5f;
  return normalize(vec3(p.x, p.y, 1.0f - abs(p.x) - abs(p.y)));
}
// Integer central direction of texel (i, j) of an S x S square, in (t, b, n):
// S times the hemi-oct point of the texel centre.
RDM_FN ivec3 texelCentralDirection(int i, int j, int S) {
  int a = i + j + 1 - S;
  int c = i - j;
  return ivec3(a, c, S - abs(a) - abs(c));
}
// Atlas pixel of texel (i, j) of face f of an RDM whose rect starts at (x, y).
RDM_FN ivec2 rdmTexelPixel(int x, int y, int S, int f, int i, int j) {
  return ivec2(x + S * (f % 2) + i, y + S * (f / 2) + j);
}
// Hemisphere size of roughness level r: min(2^(8-r), max_hemisphere), never below 2.
RDM_FN int hemisphereSize(int level, int max_hemisphere) {
  return max(2, min(1 << (8 - level), max_hemisphere));
}

// Orientation rot = 4a + b (SPEC section 1): R = T_a Ry(90 b), applied to an integer vector.
RDM_FN ivec3 rotateAboutY(int b, ivec3 v) {
  for (int q = 0; q < 4; ++q) {
    if (q < b) v = ivec3(v.z, v.y, -v.x);
  }
  return v;
}
RDM_FN ivec3 orientTransform(int a, ivec3 v) {
  if (a == 1) return ivec3(v.x, -v.y, -v.z);  // 180 about X: +Y -> -Y
  if (a == 2) return ivec3(v.y, -v.x, v.z);   // -90 about Z: +Y -> +X
  if (a == 3) return ivec3(-v.y, v.x, v.z);   // +90 about Z: +Y -> -X
  if (a == 4) return ivec3(v.x, -v.z, v.y);   // +90 about X: +Y -> +Z
  if (a == 5) return ivec3(v.x, v.z, -v.y);   // -90 about X: +Y -> -Z
  return v;
}
RDM_FN ivec3 orientVector(int rot, ivec3 v) { return orientTransform(rot / 4, rotateAboutY(rot % 4, v)); }
// Slot position of block-local voxel `local` (0..15 per axis) under orientation rot.
RDM_FN ivec3 orientVoxel(int rot, ivec3 local) {
  ivec3 q = orientVector(rot, local * 2 + ivec3(1 - kBlockSize));
  return (q + ivec3(kBlockSize - 1)) / 2;
}

// Counter-based random numbers (SPEC section 5): a 32-bit avalanche hash chained over the
// key fields; u = top 24 bits * 2^-24, in [0, 1).
RDM_FN uint hashMix(uint x) {
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}
RDM_FN uint hashCombine(uint h, uint value) { return hashMix(h ^ (value + 0x9e3779b9u)); }
// Key of one path: (seed, slot, level, texel, sample). `slot` packs i | j << 8 | k << 16;
// `texel` is face * S^2 + j * S + i. Renders use (camera, pixel) in the slot and texel places.
RDM_FN uint pathKey(uint seed, uint slot, uint level, uint texel, uint sample_index) {
  uint h = hashCombine(hashMix(seed), slot);
  h = hashCombine(h, level);
  h = hashCombine(h, texel);
  return hashCombine(h, sample_index);
}
RDM_FN float randomUniform(uint path_key, uint bounce, uint dim) {
  uint h = hashCombine(hashCombine(path_key, bounce), dim);
  return float(h >> 8) * (1.0f / 16777216.0f);
}
// Random-number dimensions, fixed per use so compiling an effect out shifts nothing.
RDM_CONST uint kDimBsdf0 = 0u;
RDM_CONST uint kDimBsdf1 = 1u;
RDM_CONST uint kDimLobe = 2u;
RDM_CONST uint kDimRoulette = 3u;
RDM_CONST uint kDimSun0 = 4u;
RDM_CONST uint kDimSun1 = 5u;
RDM_CONST uint kDimEmitterChoice = 6u;
RDM_CONST uint kDimEmitterPoint0 = 7u;
RDM_CONST uint kDimEmitterPoint1 = 8u;
RDM_CONST uint kDimOrigin0 = 9u;
RDM_CONST uint kDimOrigin1 = 10u;

#ifdef __cplusplus
}  // namespace rdm::shared
#undef RDM_FN
#undef RDM_CONST
#undef RDM_INOUT
#endif
#endif  // RDM_SHARED_H
