// RDM lookups of docs/spec.md section 6: diffuse from the level-7 maps of the slot and its face-plane
// neighbours, specular by a depth-guided march in the level of the material's roughness.
#ifndef VIEWER_RDM_LOOKUP_GLSL
#define VIEWER_RDM_LOOKUP_GLSL

#include "viewer_common.glsl"

// Per slot (linear index i + X (j + Y k)): header x = oriented block (-1 empty),
// y = faces whose level-7 central depths are not all 0 (usable for the diffuse blend),
// z = faces skipped by docs/spec.md section 3's rule, w = log2 of each level's hemisphere
// size, 4 bits per level (0: absent); face f of level l is word 6l + f of `tiles`,
// x / 2 | (y / 2) << 13 | page << 26 (kNoTilePage: not stored; gpu_layout.h).
struct SlotInfo {
  ivec4 header;
  ivec4 tiles[6 * kLevelCount / 4];
};
const int kNoTilePage = 63;
layout(std430, set = 0, binding = 2) readonly buffer Slots { SlotInfo slots[]; };

// RGB radiance, one array layer per atlas page; atlas_depth's r is the texel's Z (the same
// image's alpha through a swizzled view, or a one-channel image beside a BC6H one).
layout(set = 0, binding = 4) uniform sampler2DArray atlas;
layout(set = 0, binding = 7) uniform sampler2DArray atlas_depth;

// Reflection march (docs/spec.md section 6): kMarchSteps geometric steps from the face plane,
// the first kMarchFirstStep world units long, each kMarchGrowth times the previous (they
// reach ~26 units), then kBisectionSteps halvings of the bracketing interval. A ray that
// finds no crossing uses the stored radiance in direction R (a distant hit). 26 steps of
// growth 1.25 reach as far as 40 of 1.14 for two thirds of the fetches (docs/results.md
// section 1e).
const int kMarchSteps = 26;
const float kMarchFirstStep = 0.02;
const float kMarchGrowth = 1.25;
const int kBisectionSteps = 7;

int slotIndex(ivec3 s) { return s.x + frame.grid_size.x * (s.y + frame.grid_size.y * s.z); }
bool slotInGrid(ivec3 s) { return all(greaterThanEqual(s, ivec3(0))) && all(lessThan(s, frame.grid_size.xyz)); }

// Square coordinates of a local direction (t, b, n): continuous texel position in [0, S]^2.
vec2 squarePosition(vec3 d, int size) { return (hemiOctEncode(d) + 1.0) * 0.5 * float(size); }

// The tile of face `face` in level `level`'s map of slot `slot_index`: (atlas x, y,
// hemisphere S, page), or S = 0 when the level is absent or the face not stored.
ivec4 faceTile(int slot_index, int level, int face) {
  int log_size = (slots[slot_index].header.w >> (4 * level)) & 15;
  int word_index = 6 * level + face;
  int word = slots[slot_index].tiles[word_index >> 2][word_index & 3];
  int page = (word >> 26) & 63;
  if (log_size == 0 || page == kNoTilePage) return ivec4(0);
  return ivec4((word & 0x1fff) * 2, ((word >> 13) & 0x1fff) * 2, 1 << log_size, page);
}

float rdmDepth(ivec4 tile, vec3 d) {
  ivec2 ij = clamp(ivec2(floor(squarePosition(d, tile.z))), ivec2(0), ivec2(tile.z - 1));
  return texelFetch(atlas_depth, ivec3(tile.xy + ij, tile.w), 0).r;
}

// Bilinear radiance with the sample position clamped to texel centres of the face's
// tile: never reads a neighbouring tile (docs/spec.md section 6).
vec3 rdmRadiance(ivec4 tile, vec3 d) {
  vec2 q = clamp(squarePosition(d, tile.z), vec2(0.5), vec2(float(tile.z) - 0.5));
  vec2 px = vec2(tile.xy) + q;
  return textureLod(atlas, vec3(px * frame.atlas_size.zw, float(tile.w)), 0.0).rgb;
}

// Adds the level-7 radiance of face `face` of slot `s` with weight w when it is usable.
void accumulateDiffuse(ivec3 s, int face, float w, inout vec3 sum, inout float weight_sum) {
  if (w <= 0.0 || !slotInGrid(s)) return;
  int index = slotIndex(s);
  ivec4 header = slots[index].header;
  if (header.x < 0 || (header.y & (1 << face)) == 0) return;
  ivec4 tile = faceTile(index, kDiffuseLevel, face);
  if (tile.z == 0) return;
  sum += w * texelFetch(atlas, ivec3(tile.xy, tile.w), 0).rgb;  // level 7: one value per face
  weight_sum += w;
}

// The 2 x 2 set of face-plane slots around a point `offset` (slot units) from its slot's
// centre on face `face`: the neighbours towards its quadrant along the face's tangent (st)
// and bitangent (sb), and their bilinear weights between slot centres (fu, fw).
struct PlaneQuad {
  ivec3 st, sb;
  float fu, fw;
};
PlaneQuad planeQuad(int face, vec3 offset) {
  ivec3 t = faceTangent(face), b = faceBitangent(face);
  float u = dot(offset, vec3(t)), w = dot(offset, vec3(b));
  return PlaneQuad(u >= 0.0 ? t : -t, w >= 0.0 ? b : -b, abs(u), abs(w));
}

// docs/spec.md section 6 diffuse radiance L7 at `p01` (position in the slot, 0..1 per axis) on face `face`:
// the quadrant picks the 2 x 2 set of face-plane neighbours, weights are bilinear between
// face centres, unusable maps drop out and the rest renormalise; none left gives ambient.
vec3 rdmDiffuse(ivec3 slot, int face, vec3 p01) {
  PlaneQuad q = planeQuad(face, p01 - 0.5);
  vec3 sum = vec3(0.0);
  float weight_sum = 0.0;
  accumulateDiffuse(slot, face, (1.0 - q.fu) * (1.0 - q.fw), sum, weight_sum);
  accumulateDiffuse(slot + q.st, face, q.fu * (1.0 - q.fw), sum, weight_sum);
  accumulateDiffuse(slot + q.sb, face, (1.0 - q.fu) * q.fw, sum, weight_sum);
  accumulateDiffuse(slot + q.st + q.sb, face, q.fu * q.fw, sum, weight_sum);
  return weight_sum > 0.0 ? sum / weight_sum : frame.ambient.rgb;
}

// The face is baked (not skipped by docs/spec.md section 3's rule) and not dead.
bool faceUsable(ivec4 header, int face) { return ((header.y & ~header.z) & (1 << face)) != 0; }

// The tile whose radiance the specular term of face `face` of `slot` at roughness `level`
// reads: that level's, else level 7's; S = 0 (ambient) when the face is skipped or dead.
ivec4 specularTile(ivec3 slot, int face, int level) {
  int index = slotIndex(slot);
  ivec4 header = slots[index].header;
  if ((header.z & (1 << face)) != 0 || (header.y & (1 << face)) == 0) return ivec4(0);
  ivec4 tile = faceTile(index, level, face);
  return tile.z != 0 ? tile : faceTile(index, kDiffuseLevel, face);
}

// The specular radiance of a distant hit along r (rdmSpecular without the march): what a
// surface seen in a reflection reflects in turn.
vec3 rdmSpecularDistant(ivec3 slot, int face, int level, vec3 r) {
  ivec4 tile = specularTile(slot, face, level);
  if (tile.z == 0) return frame.ambient.rgb;
  ivec3 t = faceTangent(face), b = faceBitangent(face), n = faceNormal(face);
  return rdmRadiance(tile, vec3(dot(r, vec3(t)), dot(r, vec3(b)), dot(r, vec3(n))));
}

// docs/spec.md section 6 specular radiance along R from world point p on face `face` of `slot`, from the
// slot's RDM at roughness level `level` (level 7 when that map is absent). A skipped face
// returns ambient, and so does a face whose level-7 central depths are all 0 (its origin
// lies inside a neighbour's voxel, e.g. a tile under a chess piece: every texel is black,
// depth 0). The march works in the face frame relative to the face origin and starts
// `t_start` (world units) along r, where a voxel walk found nothing before. A crossing counts
// only from in front of the stored depth to behind it: a march that starts behind a surface
// the walk has shown the ray misses (seen from the face origin, a near object covers
// directions the ray passes beside it) first steps out of its shadow.
vec3 rdmSpecular(ivec3 slot, int face, int level, vec3 p, vec3 r, float t_start) {
  ivec4 tile = specularTile(slot, face, level);
  if (tile.z == 0) return frame.ambient.rgb;
  vec3 n = vec3(faceNormal(face)), t = vec3(faceTangent(face)), b = vec3(faceBitangent(face));
  vec3 o = p - (vec3(slot) + 0.5 + 0.5 * n);
  vec3 ol = vec3(dot(o, t), dot(o, b), dot(o, n));
  vec3 rl = vec3(dot(r, t), dot(r, b), dot(r, n));
  if (rl.z <= 0.0) return rdmRadiance(tile, rl);
  // Skip t while q.n <= 0: start just in front of the face plane.
  float t_prev = max(t_start, -ol.z / rl.z) + 1e-4;
  float step_len = kMarchFirstStep;
  float t_hit = -1.0;
  bool in_front = t_start <= 0.0;
  for (int k = 0; k < kMarchSteps; ++k) {
    float t_next = t_prev + step_len;
    vec3 q = ol + t_next * rl;
    bool behind = rdmDepth(tile, q) <= length(q);
    if (behind && in_front) {
      t_hit = t_next;
      break;
    }
    in_front = in_front || !behind;
    t_prev = t_next;
    step_len *= kMarchGrowth;
  }
  if (t_hit < 0.0) return rdmRadiance(tile, rl);
  float lo = t_prev, hi = t_hit;  // depth > |q| at lo, <= |q| at hi
  for (int k = 0; k < kBisectionSteps; ++k) {
    float mid = 0.5 * (lo + hi);
    vec3 q = ol + mid * rl;
    if (rdmDepth(tile, q) <= length(q)) hi = mid;
    else lo = mid;
  }
  return rdmRadiance(tile, ol + hi * rl);
}

// The face-plane neighbour `s` joins a specular blend at `level` when it holds a block whose
// face `face` is baked, usable and has that level's map.
bool blendNeighbourUsable(ivec3 s, int face, int level) {
  if (!slotInGrid(s)) return false;
  int index = slotIndex(s);
  ivec4 header = slots[index].header;
  return header.x >= 0 && faceUsable(header, face) && faceTile(index, level, face).z != 0;
}

// rdmSpecular blended across block boundaries (docs/spec.md section 6): the RDMs of the 2 x 2
// face-plane slots around the point, bilinear between slot centres as the diffuse blend
// (unusable neighbours drop out and the rest renormalise), so one block's RDM hands over to
// the next without a seam. Each RDM marches from the same point p. Blending only within 1/4
// block of a boundary costs about half as much for about half the gain (docs/results.md 1g).
// One call site of the march: lavapipe inlines every call into the fragment shader.
vec3 blendedRdmSpecular(ivec3 slot, int face, int level, vec3 p, vec3 r, float t_start) {
  PlaneQuad q = planeQuad(face, p - vec3(slot) - 0.5);
  bool blend = termOn(kTermBlockBlend);
  float au = blend ? q.fu : 0.0, aw = blend ? q.fw : 0.0;
  vec3 sum = vec3(0.0);
  float weight_sum = 0.0;
  for (int k = 0; k < 4; ++k) {
    bool along_t = (k & 1) != 0, along_b = (k & 2) != 0;
    float weight = (along_t ? au : 1.0 - au) * (along_b ? aw : 1.0 - aw);
    ivec3 s = slot + (along_t ? q.st : ivec3(0)) + (along_b ? q.sb : ivec3(0));
    if (weight <= 0.0 || (k > 0 && !blendNeighbourUsable(s, face, level))) continue;
    sum += weight * rdmSpecular(s, face, level, p, r, t_start);
    weight_sum += weight;
  }
  return sum / weight_sum;  // k = 0 always counts: its weight is at least 1/4 (|u|, |w| <= 1/2)
}

#endif  // VIEWER_RDM_LOOKUP_GLSL
