// Diffuse light per voxel face (docs/spec.md sections 3.2 and 6): the baked light of the
// shaded face and of its three nearest neighbours in the same plane, bilinear between face
// centres; faces that are not exposed (or not baked) drop out and the rest renormalise, so
// light follows steps, corners and carvings instead of the block grid.
#ifndef VIEWER_FACE_LIGHT_GLSL
#define VIEWER_FACE_LIGHT_GLSL

#include "rdm_lookup.glsl"

// viewer/renderer/scene_gpu.h buildFaceLightWords: slot rows, voxel words, RGB9E5 values, the
// filtered values, their count.
layout(set = 0, binding = 6) uniform usamplerBuffer face_light;

// Adds the light of face `face` of world voxel `v` with weight w when it is baked.
void accumulateFaceLight(ivec3 v, int face, float w, inout vec3 sum, inout float weight_sum) {
  ivec3 s = v >> 4;  // arithmetic shift: floor division by kBlockSize
  if (w <= 0.0 || !slotInGrid(s)) return;
  int row = int(texelFetch(face_light, slotIndex(s)).r) - 1;
  if (row < 0) return;
  ivec3 l = v - s * kBlockSize;
  int slot_count = frame.grid_size.x * frame.grid_size.y * frame.grid_size.z;
  uint word = texelFetch(face_light, slot_count + row * kBlockVoxelCount + l.x + kBlockSize * l.y +
                                         kBlockSize * kBlockSize * l.z).r;
  uint bit = 1u << uint(face);
  if ((word & bit) == 0u) return;
  int index = int(word >> 6u) + bitCount(word & (bit - 1u));
  if (termOn(kTermFaceLightFilter))
    index += int(texelFetch(face_light, textureSize(face_light) - 1).r);
  sum += w * decodeRgb9e5(texelFetch(face_light, index).r);
  weight_sum += w;
}

// Diffuse radiance at `q` (slot-local voxel units, on the plane of face `face`) of `slot`;
// false when none of the four faces is baked.
bool faceLightDiffuse(ivec3 slot, int face, vec3 q, out vec3 light) {
  vec3 n = vec3(faceNormal(face));
  ivec3 t = faceTangent(face), b = faceBitangent(face);
  ivec3 v = clamp(ivec3(floor(q - 0.5 * n)), ivec3(0), ivec3(kBlockSize - 1)) + slot * kBlockSize;
  vec3 offset = q - (vec3(v - slot * kBlockSize) + 0.5);
  float u = dot(offset, vec3(t)), w = dot(offset, vec3(b));
  ivec3 st = u >= 0.0 ? t : -t, sb = w >= 0.0 ? b : -b;
  float fu = min(abs(u), 1.0), fw = min(abs(w), 1.0);
  vec3 sum = vec3(0.0);
  float weight_sum = 0.0;
  accumulateFaceLight(v, face, (1.0 - fu) * (1.0 - fw), sum, weight_sum);
  accumulateFaceLight(v + st, face, fu * (1.0 - fw), sum, weight_sum);
  accumulateFaceLight(v + sb, face, (1.0 - fu) * fw, sum, weight_sum);
  accumulateFaceLight(v + st + sb, face, fu * fw, sum, weight_sum);
  light = weight_sum > 0.0 ? sum / weight_sum : vec3(0.0);
  return weight_sum > 0.0;
}

// Level-7 diffuse radiance L7 at p01 (0..1 in the slot) on face `face`: the face light where
// the term is on and it is baked, the RDMs otherwise.
vec3 diffuseRadiance(ivec3 slot, int face, vec3 p01) {
  vec3 light;
  if (termOn(kTermFaceLight) && faceLightDiffuse(slot, face, p01 * float(kBlockSize), light))
    return light;
  return rdmDiffuse(slot, face, p01);
}

#endif  // VIEWER_FACE_LIGHT_GLSL
