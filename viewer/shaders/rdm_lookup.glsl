// RDM lookups of docs/spec.md section 6: diffuse from the level-7 maps of the slot and its face-plane
// neighbours, specular by a depth-guided march in the level of the material's roughness.
#ifndef VIEWER_RDM_LOOKUP_GLSL
#define VIEWER_RDM_LOOKUP_GLSL

#include "viewer_common.glsl"

// Per slot (linear index i + X (j + Y k)): header x = oriented block (-1 empty),
// y = faces whose level-7 central depths are not all 0 (usable for the diffuse blend),
// z = faces skipped by docs/spec.md section 3's rule; rdm[level] = (atlas x, y, hemisphere S or 0, page).
struct SlotInfo {
  ivec4 header;
  ivec4 rdm[kLevelCount];
};
layout(std430, set = 0, binding = 2) readonly buffer Slots { SlotInfo slots[]; };

// RGB radiance and Z depth, one array layer per atlas page.
layout(set = 0, binding = 4) uniform sampler2DArray atlas;

// Reflection march (formulas.md 4.5): kMarchSteps geometric steps from the face plane,
// the first kMarchFirstStep world units long, each kMarchGrowth times the previous (they
// reach ~27 units), then kBisectionSteps halvings of the bracketing interval. A ray that
// finds no crossing uses the stored radiance in direction R (a distant hit).
const int kMarchSteps = 40;
const float kMarchFirstStep = 0.02;
const float kMarchGrowth = 1.14;
const int kBisectionSteps = 6;

int slotIndex(ivec3 s) { return s.x + frame.grid_size.x * (s.y + frame.grid_size.y * s.z); }
bool slotInGrid(ivec3 s) { return all(greaterThanEqual(s, ivec3(0))) && all(lessThan(s, frame.grid_size.xyz)); }

// Square coordinates of a local direction (t, b, n): continuous texel position in [0, S]^2.
vec2 squarePosition(vec3 d, int size) { return (hemiOctEncode(d) + 1.0) * 0.5 * float(size); }

float rdmDepth(ivec4 rect, int face, vec3 d) {
  ivec2 ij = clamp(ivec2(floor(squarePosition(d, rect.z))), ivec2(0), ivec2(rect.z - 1));
  ivec2 px = rdmTexelPixel(rect.x, rect.y, rect.z, face, ij.x, ij.y);
  return texelFetch(atlas, ivec3(px, rect.w), 0).a;
}

// Bilinear radiance with the sample position clamped to texel centres of the face's
// square: never reads a neighbouring face (docs/spec.md section 6).
vec3 rdmRadiance(ivec4 rect, int face, vec3 d) {
  vec2 q = clamp(squarePosition(d, rect.z), vec2(0.5), vec2(float(rect.z) - 0.5));
  vec2 px = vec2(rect.xy) + vec2(float(rect.z * (face % 2)), float(rect.z * (face / 2))) + q;
  return textureLod(atlas, vec3(px * frame.atlas_size.zw, float(rect.w)), 0.0).rgb;
}

// Adds the level-7 radiance of face `face` of slot `s` with weight w when it is usable.
void accumulateDiffuse(ivec3 s, int face, float w, inout vec3 sum, inout float weight_sum) {
  if (w <= 0.0 || !slotInGrid(s)) return;
  SlotInfo info = slots[slotIndex(s)];
  ivec4 rect = info.rdm[kDiffuseLevel];
  if (info.header.x < 0 || rect.z == 0 || (info.header.y & (1 << face)) == 0) return;
  ivec2 px = rdmTexelPixel(rect.x, rect.y, rect.z, face, 0, 0);  // level 7: one value per face
  sum += w * texelFetch(atlas, ivec3(px, rect.w), 0).rgb;
  weight_sum += w;
}

// docs/spec.md section 6 diffuse radiance L7 at `p01` (position in the slot, 0..1 per axis) on face `face`:
// the quadrant picks the 2 x 2 set of face-plane neighbours, weights are bilinear between
// face centres, unusable maps drop out and the rest renormalise; none left gives ambient.
vec3 rdmDiffuse(ivec3 slot, int face, vec3 p01) {
  ivec3 t = faceTangent(face), b = faceBitangent(face);
  float u = dot(p01 - 0.5, vec3(t)), w = dot(p01 - 0.5, vec3(b));
  ivec3 st = u >= 0.0 ? t : -t, sb = w >= 0.0 ? b : -b;
  float fu = abs(u), fw = abs(w);
  vec3 sum = vec3(0.0);
  float weight_sum = 0.0;
  accumulateDiffuse(slot, face, (1.0 - fu) * (1.0 - fw), sum, weight_sum);
  accumulateDiffuse(slot + st, face, fu * (1.0 - fw), sum, weight_sum);
  accumulateDiffuse(slot + sb, face, (1.0 - fu) * fw, sum, weight_sum);
  accumulateDiffuse(slot + st + sb, face, fu * fw, sum, weight_sum);
  return weight_sum > 0.0 ? sum / weight_sum : frame.ambient.rgb;
}

// docs/spec.md section 6 specular radiance along R from world point p on face `face` of `slot`, from the
// slot's RDM at roughness level `level` (level 7 when that map is absent). A skipped face
// returns ambient, and so does a face whose level-7 central depths are all 0 (its origin
// lies inside a neighbour's voxel, e.g. a tile under a chess piece: every texel is black,
// depth 0). The march works in the face frame relative to the face origin.
vec3 rdmSpecular(ivec3 slot, int face, int level, vec3 p, vec3 r) {
  SlotInfo info = slots[slotIndex(slot)];
  if ((info.header.z & (1 << face)) != 0 || (info.header.y & (1 << face)) == 0) return frame.ambient.rgb;
  ivec4 rect = info.rdm[level];
  if (rect.z == 0) rect = info.rdm[kDiffuseLevel];
  if (rect.z == 0) return frame.ambient.rgb;
  vec3 n = vec3(faceNormal(face)), t = vec3(faceTangent(face)), b = vec3(faceBitangent(face));
  vec3 o = p - (vec3(slot) + 0.5 + 0.5 * n);
  vec3 ol = vec3(dot(o, t), dot(o, b), dot(o, n));
  vec3 rl = vec3(dot(r, t), dot(r, b), dot(r, n));
  if (rl.z <= 0.0) return rdmRadiance(rect, face, rl);
  // Skip t while q.n <= 0: start just in front of the face plane.
  float t_prev = max(0.0, -ol.z / rl.z) + 1e-4;
  float step_len = kMarchFirstStep;
  float t_hit = -1.0;
  for (int k = 0; k < kMarchSteps; ++k) {
    float t_next = t_prev + step_len;
    vec3 q = ol + t_next * rl;
    if (rdmDepth(rect, face, q) <= length(q)) {
      t_hit = t_next;
      break;
    }
    t_prev = t_next;
    step_len *= kMarchGrowth;
  }
  if (t_hit < 0.0) return rdmRadiance(rect, face, rl);
  float lo = t_prev, hi = t_hit;  // depth > |q| at lo, <= |q| at hi
  for (int k = 0; k < kBisectionSteps; ++k) {
    float mid = 0.5 * (lo + hi);
    vec3 q = ol + mid * rl;
    if (rdmDepth(rect, face, q) <= length(q)) hi = mid;
    else lo = mid;
  }
  return rdmRadiance(rect, face, ol + hi * rl);
}

#endif  // VIEWER_RDM_LOOKUP_GLSL
