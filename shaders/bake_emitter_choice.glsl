// Emitter choice of the bake kernel (docs/spec.md sections 3.2 and 5), part of bake.comp: included
// after its buffers, which it reads (params, emitter_cdf, slot_first), and its g_slot. Every
// loop runs a fixed count, which the caller adds to the loop accounting through g_searched.
#ifndef RDM_BAKE_EMITTER_CHOICE_GLSL
#define RDM_BAKE_EMITTER_CHOICE_GLSL

float emitterPdf(vec3 radiance, float dist2, float cos_e) {
  return emitterSolidAnglePdf(params.sky_zenith.w, radiance, dist2, cos_e);  // w: total luminance
}

// The first index in [lo, hi) whose cdf exceeds u (std::upper_bound); hi when none. A fixed
// 32-step search (enough for any count) so every lane runs the same iterations.
uint cdfUpperBound(uint lo, uint hi, float u) {
  for (int n = 0; n < 32; ++n) {
    if (lo < hi) {
      uint mid = lo + (hi - lo) / 2u;
      if (emitter_cdf[mid] <= u) {
        lo = mid + 1u;
      } else {
        hi = mid;
      }
    }
  }
  return lo;
}

// EmitterList::pick: the emitter whose cdf first exceeds u, clamped.
uint g_searched = 0u;
int pickEmitter(float u) {
  int count = int(params.config.z);
  g_searched = 32u;
  return min(int(cdfUpperBound(0u, uint(count), u)), count - 1);
}

// The face light's local emitter choice (integrator.cpp pickFaceLightEmitter): the slots within
// one slot of g_slot, z, then y, then x from -1 to 1; local_sum comes with the job.
float cdfMass(uint begin, uint end) {
  return end > begin ? emitter_cdf[end - 1u] - (begin > 0u ? emitter_cdf[begin - 1u] : 0.0f) : 0.0f;
}
int nearSlotIndex(int n) {  // -1 outside the grid
  ivec3 s = g_slot + ivec3(n % 3 - 1, (n / 3) % 3 - 1, n / 9 - 1);
  if (any(lessThan(s, ivec3(0))) || any(greaterThanEqual(s, params.world.xyz))) return -1;
  return s.x + params.world.x * (s.y + params.world.y * s.z);
}
int pickFaceLightEmitter(float local_sum, float u) {
  float a = faceLightLocalShare(local_sum);
  if (!(u < a)) return pickEmitter((u - a) / (1.0f - a));
  float v = u / a * local_sum;
  float acc = 0.0f;
  float before = 0.0f;
  uint begin = 0u;
  uint end = 0u;
  for (int n = 0; n < 27; ++n) {
    int i = nearSlotIndex(n);
    if (i < 0) continue;
    float mass = cdfMass(slot_first[i], slot_first[i + 1]);
    if (!(mass > 0.0f)) continue;
    begin = slot_first[i];
    end = slot_first[i + 1];
    before = acc;
    acc += mass;
    if (v < acc) break;
  }
  float target = (begin > 0u ? emitter_cdf[begin - 1u] : 0.0f) + (v - before);
  return min(int(cdfUpperBound(begin, end, target)), int(end) - 1);
}

#endif  // RDM_BAKE_EMITTER_CHOICE_GLSL
