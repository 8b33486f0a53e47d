// Conventions shared by the C++ core, the Vulkan bake kernels and the viewer shaders
// (docs/spec.md sections 1, 3 and 5). Written in the common subset of GLSL 4.50 and C++ with GLM,
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

// Material byte m of a voxel [r, g, b, m] (docs/spec.md section 1).
RDM_CONST uint kSolidBit = 0x80u;
RDM_FN bool materialSolid(uint m) { return (m & kSolidBit) != 0u; }
RDM_FN int materialRoughness(uint m) { return int(m & 7u); }
RDM_FN int materialMetallic(uint m) { return int((m >> 3) & 3u); }
RDM_FN int materialEmission(uint m) { return int((m >> 5) & 3u); }
RDM_FN uint packMaterial(int roughness, int metallic, int emission) {
  return kSolidBit | uint(roughness) | (uint(metallic) << 3) | (uint(emission) << 5);
}
// Metallic factor of metallic level 0..3, and the Schlick F0 (1 - m) 0.04 + m c.
RDM_FN float metallicFactor(int level) { return float(level) / 3.0f; }
RDM_FN vec3 materialF0(vec3 base_color, float metallic) {
  return vec3((1.0f - metallic) * 0.04f) + metallic * base_color;
}
// GGX alpha of roughness level r: (r/7)^2.
RDM_FN float roughnessAlpha(int level) {
  float r = float(level) / 7.0f;
  return r * r;
}

// Face frames (t, b, n), right-handed, docs/spec.md section 3.
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
// Pixel of texel (i, j) of face f in a 2S x 3S RDM image placed at (x, y) (the atlas itself
// stores each face as its own S x S tile, docs/spec.md section 4).
RDM_FN ivec2 rdmTexelPixel(int x, int y, int S, int f, int i, int j) {
  return ivec2(x + S * (f % 2) + i, y + S * (f / 2) + j);
}
// Hemisphere size of roughness level r: min(2^(8-r), max_hemisphere), never below 2.
RDM_FN int hemisphereSize(int level, int max_hemisphere) {
  return max(2, min(1 << (8 - level), max_hemisphere));
}

// Orientation rot = 4a + b (docs/spec.md section 1): R = T_a Ry(90 b), applied to an integer vector.
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

// Counter-based random numbers (docs/spec.md section 5): a 32-bit avalanche hash chained over the
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
// Face light (docs/spec.md section 3.2): the point on the voxel face, at bounce 0.
RDM_CONST uint kDimFacePoint0 = 11u;
RDM_CONST uint kDimFacePoint1 = 12u;
// Glass (docs/spec.md section 5): the dielectric or the opaque surface, then reflection or
// refraction at the interface.
RDM_CONST uint kDimGlassChoice = 13u;
RDM_CONST uint kDimFresnel = 14u;

// Unpolarised Fresnel reflectance of a smooth dielectric interface met at cos_i > 0 from the
// side of index n1 towards index n2, eta = n1 / n2; 1 under total internal reflection.
RDM_FN float fresnelDielectric(float cos_i, float eta) {
  float sin2_t = eta * eta * max(0.0f, 1.0f - cos_i * cos_i);
  if (sin2_t >= 1.0f) return 1.0f;
  float cos_t = sqrt(1.0f - sin2_t);
  float rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  float rp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  return 0.5f * (rs * rs + rp * rp);
}
// The refraction of unit direction d at an interface with unit normal n facing against d
// (dot(d, n) < 0), eta = n1 / n2; only where fresnelDielectric is below 1.
RDM_FN vec3 refractDirection(vec3 d, vec3 n, float eta) {
  float cos_i = -dot(d, n);
  float cos_t = sqrt(max(0.0f, 1.0f - eta * eta * max(0.0f, 1.0f - cos_i * cos_i)));
  return normalize(eta * d + (eta * cos_i - cos_t) * n);
}

// Face light: the `level` field of its path keys (RDM levels are 0..7) and its `texel`
// field, voxel index (x + 16 y + 256 z, slot space) * 6 + face.
RDM_CONST uint kFaceLightLevel = 8u;
RDM_FN uint faceLightTexel(int voxel_index, int face) { return uint(voxel_index * kFaceCount + face); }

// Shared-exponent RGB (the layout of Vulkan's E5B9G9R9_UFLOAT_PACK32): 9-bit mantissas of
// R, G, B at bits 0, 9, 18 and a 5-bit exponent (bias 15) at bit 27; value m * 2^(e - 24).
RDM_FN vec3 decodeRgb9e5(uint word) {
  float scale = exp2(float(int(word >> 27u) - 24));
  return vec3(float(word & 511u), float((word >> 9u) & 511u), float((word >> 18u) & 511u)) * scale;
}


// ---------------------------------------------------------------------------------------
// Transport math shared with the Vulkan bake kernels (docs/spec.md section 5). Each function is the
// operation-for-operation twin of the CPU's (bsdf.cpp, sampling.h, lights.h, integrator.h);
// tests/vulkan/vulkan_test.cpp checks that the C++ compilation of these equals the CPU's bit for bit.
RDM_CONST float kPiF = 3.14159265358979323846f;

RDM_FN bool finiteFloat(float x) {
#ifdef __cplusplus
  return std::isfinite(x);
#else
  return !isnan(x) && !isinf(x);
#endif
}
RDM_FN bool finiteVec3(vec3 v) { return finiteFloat(v.x) && finiteFloat(v.y) && finiteFloat(v.z); }
// Rec. 709 luminance (rdm::luminance).
RDM_FN float lumaRec709(vec3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }
// Power heuristic a^2 / (a^2 + b^2), 0 when both vanish.
RDM_FN float misPowerHeuristic(float a, float b) {
  float a2 = a * a;
  float b2 = b * b;
  return a2 + b2 > 0.0f ? a2 / (a2 + b2) : 0.0f;
}

// Orthonormal frame (t, b, n); the face frames are faceTangent/faceBitangent/faceNormal.
struct ShFrame {
  vec3 t;
  vec3 b;
  vec3 n;
};
RDM_FN vec3 frameToLocal(ShFrame f, vec3 v) { return vec3(dot(v, f.t), dot(v, f.b), dot(v, f.n)); }
RDM_FN vec3 frameToWorld(ShFrame f, vec3 v) { return f.t * v.x + f.b * v.y + f.n * v.z; }
RDM_FN ShFrame faceFrameOf(int face) {
  ShFrame f;
  f.t = vec3(faceTangent(face));
  f.b = vec3(faceBitangent(face));
  f.n = vec3(faceNormal(face));
  return f;
}
// Duff et al. 2017 basis around a unit vector (rdm::frameAround).
RDM_FN ShFrame frameAroundDir(vec3 n) {
#ifdef __cplusplus
  float sign = std::copysign(1.0f, n.z);
#else
  float sign = (floatBitsToUint(n.z) & 0x80000000u) != 0u ? -1.0f : 1.0f;
#endif
  float a = -1.0f / (sign + n.z);
  float b = n.x * n.y * a;
  ShFrame f;
  f.t = vec3(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
  f.b = vec3(b, sign + n.y * n.y * a, -n.y);
  f.n = n;
  return f;
}
RDM_FN vec3 sampleCosineDir(float u0, float u1) {
  float r = sqrt(u0);
  float phi = 2.0f * kPiF * u1;
  return vec3(r * cos(phi), r * sin(phi), sqrt(max(0.0f, 1.0f - u0)));
}
RDM_FN vec3 sampleConeDir(float one_minus_cos_max, float u0, float u1) {
  float one_minus_cos = u0 * one_minus_cos_max;
  float sin_theta = sqrt(max(0.0f, one_minus_cos * (2.0f - one_minus_cos)));
  float phi = 2.0f * kPiF * u1;
  return vec3(sin_theta * cos(phi), sin_theta * sin(phi), 1.0f - one_minus_cos);
}

// The metallic-roughness BSDF in the surface's local frame (z = n).
struct BsdfMaterial {
  vec3 base_color;  // linear
  vec3 f0;          // (1 - m) 0.04 + m c
  float metallic;
  float alpha;      // GGX alpha = (r/7)^2; 0 is a true mirror
};
RDM_FN float bsdfGgxD(float n_dot_h, float alpha) {
  float a2 = alpha * alpha;
  float c2 = n_dot_h * n_dot_h;
  float denom = max(0.0f, 1.0f - c2) + c2 * a2;
  denom = max(denom, 1e-15f);
  return a2 / (kPiF * denom * denom);
}
RDM_FN float bsdfVisibility(float n_dot_v, float n_dot_l, float alpha) {
  float a2 = alpha * alpha;
  float gv = n_dot_l * sqrt(n_dot_v * n_dot_v * (1.0f - a2) + a2);
  float gl = n_dot_v * sqrt(n_dot_l * n_dot_l * (1.0f - a2) + a2);
  float denom = gv + gl;
  return denom > 0.0f ? 0.5f / denom : 0.0f;
}
RDM_FN float bsdfG1OverCos(float n_dot_v, float alpha) {
  float a2 = alpha * alpha;
  return 2.0f / (n_dot_v + sqrt(n_dot_v * n_dot_v * (1.0f - a2) + a2));
}
RDM_FN vec3 bsdfFresnel(vec3 f0, float cos_theta) {
  float x = 1.0f - cos_theta;
  float x2 = x * x;
  return f0 + (vec3(1.0f) - f0) * (x2 * x2 * x);
}
RDM_FN vec3 bsdfSampleVndf(vec3 v, float alpha, float u0, float u1) {
  vec3 vh = normalize(vec3(alpha * v.x, alpha * v.y, v.z));
  float len2 = vh.x * vh.x + vh.y * vh.y;
  vec3 t1 = len2 > 0.0f ? vec3(-vh.y, vh.x, 0.0f) / sqrt(len2) : vec3(1.0f, 0.0f, 0.0f);
  vec3 t2 = cross(vh, t1);
  float r = sqrt(u0);
  float phi = 2.0f * kPiF * u1;
  float p1 = r * cos(phi);
  float p2 = r * sin(phi);
  float s = 0.5f * (1.0f + vh.z);
  p2 = (1.0f - s) * sqrt(max(0.0f, 1.0f - p1 * p1)) + s * p2;
  vec3 nh = p1 * t1 + p2 * t2 + sqrt(max(0.0f, 1.0f - p1 * p1 - p2 * p2)) * vh;
  return normalize(vec3(alpha * nh.x, alpha * nh.y, max(0.0f, nh.z)));
}
RDM_FN vec3 bsdfSampleNdf(float alpha, float u0, float u1) {
  float a2 = alpha * alpha;
  float cos2 = (1.0f - u0) / (1.0f + (a2 - 1.0f) * u0);
  float cos_t = sqrt(clamp(cos2, 0.0f, 1.0f));
  float sin_t = sqrt(max(0.0f, 1.0f - cos2));
  float phi = 2.0f * kPiF * u1;
  return vec3(sin_t * cos(phi), sin_t * sin(phi), cos_t);
}
RDM_FN bool bsdfHasSmoothLobe(BsdfMaterial m) { return m.alpha > 0.0f || m.metallic < 1.0f; }
RDM_FN float bsdfSpecularProbability(BsdfMaterial m, float n_dot_v) {
  if (m.metallic >= 1.0f) return 1.0f;
  float fs = lumaRec709(bsdfFresnel(m.f0, n_dot_v));
  float fd = (1.0f - m.metallic) * (1.0f - fs) * lumaRec709(m.base_color);
  float p = fs / max(fs + fd, 1e-12f);
  return clamp(p, 0.05f, 0.95f);
}
RDM_FN vec3 bsdfDiffuseTerm(BsdfMaterial m, vec3 v, vec3 l) {
  vec3 h = normalize(v + l);
  vec3 f = bsdfFresnel(m.f0, clamp(dot(v, h), 0.0f, 1.0f));
  return (1.0f - m.metallic) * (vec3(1.0f) - f) * m.base_color / kPiF;
}
RDM_FN vec3 bsdfSpecularTerm(BsdfMaterial m, vec3 v, vec3 l) {
  vec3 h = normalize(v + l);
  float d = bsdfGgxD(h.z, m.alpha);
  vec3 f = bsdfFresnel(m.f0, clamp(dot(v, h), 0.0f, 1.0f));
  return d * bsdfVisibility(v.z, l.z, m.alpha) * f;
}
RDM_FN float bsdfSpecularPdf(BsdfMaterial m, vec3 v, vec3 l) {
  vec3 h = normalize(v + l);
  if (h.z <= 0.0f) return 0.0f;
  return bsdfGgxD(h.z, m.alpha) * bsdfG1OverCos(v.z, m.alpha) * 0.25f;
}
// f(v, l) without the delta component.
RDM_FN vec3 bsdfEval(BsdfMaterial m, vec3 v, vec3 l) {
  if (v.z <= 0.0f || l.z <= 0.0f) return vec3(0.0f);
  vec3 f = m.metallic < 1.0f ? bsdfDiffuseTerm(m, v, l) : vec3(0.0f);
  if (m.alpha > 0.0f) f += bsdfSpecularTerm(m, v, l);
  return f;
}
// Pdf of bsdfSample producing l, excluding the delta lobe.
RDM_FN float bsdfPdf(BsdfMaterial m, vec3 v, vec3 l) {
  if (v.z <= 0.0f || l.z <= 0.0f) return 0.0f;
  float p_spec = bsdfSpecularProbability(m, v.z);
  float pdf = (1.0f - p_spec) * l.z / kPiF;
  if (m.alpha > 0.0f) pdf += p_spec * bsdfSpecularPdf(m, v, l);
  return pdf;
}
struct BsdfDraw {
  vec3 l;       // local
  vec3 weight;  // f cos / pdf, or the delta lobe's weight
  float pdf;    // 0 for a delta sample
  bool delta;
  bool valid;
};
RDM_FN BsdfDraw bsdfSample(BsdfMaterial m, vec3 v, float u0, float u1, float u_lobe) {
  BsdfDraw s;
  s.l = vec3(0.0f);
  s.weight = vec3(0.0f);
  s.pdf = 0.0f;
  s.delta = false;
  s.valid = false;
  if (v.z <= 0.0f) return s;
  float p_spec = bsdfSpecularProbability(m, v.z);
  bool specular = u_lobe < p_spec;
  if (specular && m.alpha == 0.0f) {
    s.l = vec3(-v.x, -v.y, v.z);
    s.weight = bsdfFresnel(m.f0, v.z) / p_spec;
    s.delta = true;
    s.valid = finiteVec3(s.weight);
    return s;
  }
  if (specular) {
    vec3 h = bsdfSampleVndf(v, m.alpha, u0, u1);
    s.l = 2.0f * dot(v, h) * h - v;
  } else {
    s.l = sampleCosineDir(u0, u1);
  }
  if (s.l.z <= 0.0f) return s;
  s.pdf = bsdfPdf(m, v, s.l);
  if (!(s.pdf > 0.0f) || !finiteFloat(s.pdf)) return s;
  s.weight = bsdfEval(m, v, s.l) * s.l.z / s.pdf;
  s.valid = finiteVec3(s.weight);
  return s;
}
// Hits of the voxel walk (docs/spec.md section 5). `mask` bit a: axis a was crossed on the
// step that entered the hit voxel. The entry axis is the first crossed axis with the
// largest |d| (-1 when none was crossed: the walk started inside a solid voxel).
RDM_FN int entryAxis(int mask, vec3 d) {
  int best = -1;
  if ((mask & 1) != 0) best = 0;
  if ((mask & 2) != 0 && (best < 0 || abs(d.y) > abs(d[best]))) best = 1;
  if ((mask & 4) != 0 && (best < 0 || abs(d.z) > abs(d[best]))) best = 2;
  return best;
}
// Face 0..5 of the hit voxel that the ray entered through on `axis`.
RDM_FN int entryFace(int axis, float d_axis) { return 2 * axis + (d_axis > 0.0f ? 1 : 0); }
// The hit point o + t d put on the entry face of `voxel`, clamped into the voxel's extent.
RDM_FN vec3 entryPoint(vec3 o, vec3 d, float t, ivec3 voxel, int axis) {
  vec3 p = clamp(o + t * d, vec3(voxel), vec3(voxel + 1));
  p[axis] = float(voxel[axis] + (d[axis] > 0.0f ? 0 : 1));
  return p;
}

// Path origins of docs/spec.md section 3, drawn from (u0, u1) on face frame `frame`. An
// untraced draw adds radiance 0 at its weight: below the face, levels 0 and 7 count it at
// weight 1 and the rough levels leave it out of both sums (weight 0).
struct OriginDraw {
  vec3 dir;      // world, unit
  float weight;  // in the texel's weighted mean: 1, or w.l at the rough levels
  bool traced;
};
// The hemi-oct point (u0, u1) of texel (i, j)'s footprint in an S x S map, in [-1, 1]^2.
RDM_FN vec2 texelFootprintPoint(int i, int j, int S, float u0, float u1) {
  return vec2(2.0f * (float(i) + u0) / float(S) - 1.0f, 2.0f * (float(j) + u1) / float(S) - 1.0f);
}
// Level 0: uniform over texel (i, j)'s hemi-oct footprint of an S x S map.
RDM_FN OriginDraw originTexelDraw(ShFrame frame, int i, int j, int S, float u0, float u1) {
  vec2 uv = texelFootprintPoint(i, j, S, u0, u1);
  OriginDraw o;
  o.dir = frameToWorld(frame, hemiOctDecode(uv));
  o.weight = 1.0f;
  o.traced = dot(o.dir, frame.n) > 0.0f;
  return o;
}
// Rough levels 1-6: a GGX half vector (alpha) around the texel's central direction w,
// reflected, weighted by w.l (prefiltered importance sampling).
RDM_FN OriginDraw originLobeDraw(ShFrame frame, vec3 w, float alpha, float u0, float u1) {
  vec3 h = frameToWorld(frameAroundDir(w), bsdfSampleNdf(alpha, u0, u1));
  vec3 l = 2.0f * dot(w, h) * h - w;
  float wl = dot(w, l);
  OriginDraw o;
  o.traced = !(dot(frame.n, l) <= 0.0f || wl <= 0.0f);
  o.dir = o.traced ? normalize(l) : l;
  o.weight = o.traced ? wl : 0.0f;
  return o;
}
// Level 7: cosine-distributed over the face's hemisphere.
RDM_FN OriginDraw originCosineDraw(ShFrame frame, float u0, float u1) {
  vec3 local = sampleCosineDir(u0, u1);
  OriginDraw o;
  o.dir = frameToWorld(frame, local);
  o.weight = 1.0f;
  o.traced = !(local.z <= 0.0f);
  return o;
}

// Face light (docs/spec.md section 3.2): the origin of a path of face `face` of voxel `voxel`
// (global, voxel units) at draws (u0, u1) of kDimFacePoint0/1. Each draw moves to the centre of
// its 2^-24 cell, so the point never lies on the face's edge (where the walk's boundary rule
// could start in the solid neighbour); the point lies on the face's plane, which the walk
// assigns to the empty cell in front. Exact in float: the frame's axes are unit axes.
RDM_FN vec3 faceLightOrigin(ivec3 voxel, int face, float u0, float u1) {
  ShFrame f = faceFrameOf(face);
  vec3 centre = vec3(voxel) + 0.5f + 0.5f * f.n;
  float u = u0 + 0.5f / 16777216.0f;
  float w = u1 + 0.5f / 16777216.0f;
  return centre + (u - 0.5f) * f.t + (w - 0.5f) * f.b;
}

// Emitter next-event estimation (docs/spec.md section 5): the point (u0, u1) on face `face`
// of voxel `voxel`, voxel units (faces have unit area), and the solid-angle pdf of picking
// a face of `radiance` by luminance out of `total_luminance`, seen at squared distance dist2
// under cosine cos_e.
RDM_FN vec3 emitterFacePoint(ivec3 voxel, int face, float u0, float u1) {
  int axis = face / 2;
  vec3 q = vec3(voxel);
  q[axis] += face % 2 == 0 ? 1.0f : 0.0f;
  q[(axis + 1) % 3] += u0;
  q[(axis + 2) % 3] += u1;
  return q;
}
RDM_FN float emitterSolidAnglePdf(float total_luminance, vec3 radiance, float dist2, float cos_e) {
  if (!(cos_e > 0.0f) || total_luminance <= 0.0f) return 0.0f;
  float pick = max(lumaRec709(radiance), 1e-20f) / total_luminance;
  return pick * dist2 / cos_e;
}

// Face light emitter choice (docs/spec.md section 3.2): when the slots within one slot of the
// face's slot hold emitters (CDF mass local_sum > 0 of the world's emitter CDF), with probability
// kFaceLightLocalShare one of theirs by luminance, else one of the world's by luminance. An
// emitter of pick probability g (its luminance over the total) is then chosen with probability
// g * faceLightPickFactor(local_sum, near), near: it lies in one of those slots.
RDM_CONST float kFaceLightLocalShare = 0.75f;
RDM_FN float faceLightLocalShare(float local_sum) { return local_sum > 0.0f ? kFaceLightLocalShare : 0.0f; }
RDM_FN float faceLightPickFactor(float local_sum, bool near) {
  float a = faceLightLocalShare(local_sum);
  return (1.0f - a) + (near && a > 0.0f ? a / local_sum : 0.0f);
}
RDM_FN bool slotsAdjacent(ivec3 a, ivec3 b) {
  ivec3 d = abs(a - b);
  return max(d.x, max(d.y, d.z)) <= 1;
}

// Face light next-event estimation (docs/spec.md section 3.2): the face receives as a white
// Lambertian surface, whose path directions are drawn with pdf cos / pi. An emitter sample at
// cosine cos_l (to the face normal) with solid-angle pdf pdf_e adds the value below; an
// emitter the path's first segment hits is weighted by misPowerHeuristic(cos / pi, pdf_e).
RDM_FN float faceLightDirectionPdf(float cos_l) { return cos_l / kPiF; }
RDM_FN vec3 faceLightEmitterSample(vec3 radiance, float cos_l, float pdf_e) {
  if (!(pdf_e > 0.0f) || !finiteFloat(pdf_e)) return vec3(0.0f);
  float pdf_l = faceLightDirectionPdf(cos_l);
  return radiance * (pdf_l * misPowerHeuristic(pdf_e, pdf_l) / pdf_e);
}

// Sky gradient radiance (rdm::SkyLight::radiance).
RDM_FN vec3 skyGradient(vec3 zenith, vec3 horizon, vec3 ground, vec3 d) {
  return d.y >= 0.0f ? horizon + (zenith - horizon) * d.y : ground;
}

#ifdef __cplusplus
}  // namespace rdm::shared
#undef RDM_FN
#undef RDM_CONST
#undef RDM_INOUT
#endif
#endif  // RDM_SHARED_H
