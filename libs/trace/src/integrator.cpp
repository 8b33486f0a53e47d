#include "rdm/trace/integrator.h"

#include <algorithm>

namespace rdm::detail {

float emitterSolidAnglePdf(const VoxelWorld& world, const glm::vec3& radiance, float dist2,
                           float cos_e) {
  return shared::emitterSolidAnglePdf(world.emitters.total_luminance, radiance, dist2, cos_e);
}

EmitterPoint pickEmitterPoint(const VoxelWorld& world, uint32_t key, uint32_t bounce) {
  const EmitterList& list = world.emitters;
  const Emitter& e =
      list.emitters[list.pick(shared::randomUniform(key, bounce, shared::kDimEmitterChoice))];
  return {&e, shared::emitterFacePoint(
                  e.voxel, e.face, shared::randomUniform(key, bounce, shared::kDimEmitterPoint0),
                  shared::randomUniform(key, bounce, shared::kDimEmitterPoint1))};
}

glm::vec3 emitterContribution(const VoxelWorld& world, const Material& m, const glm::vec3& v_local,
                              const glm::vec3& l_local, const EmitterPoint& e, float dist2,
                              float cos_e, const TraceHit& hit, const glm::vec3& transmittance,
                              bool crossed) {
  if (!hit.hit || hit.voxel != e.emitter->voxel || hit.axis != e.emitter->face / 2)
    return glm::vec3(0.0f);
  float pdf_e = emitterSolidAnglePdf(world, e.emitter->radiance, dist2, cos_e);
  if (!(pdf_e > 0.0f) || !std::isfinite(pdf_e)) return glm::vec3(0.0f);
  float w = crossed ? 1.0f : powerHeuristic(pdf_e, pdfBsdf(m, v_local, l_local));
  return evalBsdf(m, v_local, l_local) * e.emitter->radiance * transmittance *
         (l_local.z * w / pdf_e);
}

namespace {

// CDF mass of emitters [begin, end) of the world's list.
float cdfMass(const std::vector<float>& cdf, uint32_t begin, uint32_t end) {
  return end > begin ? cdf[end - 1] - (begin > 0 ? cdf[begin - 1] : 0.0f) : 0.0f;
}

// Calls fn(begin, end) for the emitter ranges of the slots within one slot of `slot`, z, then y,
// then x from -1 to 1, inside the grid; stops when fn returns true.
template <class Fn>
void forNearSlots(const VoxelWorld& world, const glm::ivec3& slot, Fn fn) {
  const std::vector<uint32_t>& first = world.emitters.slot_first;
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const glm::ivec3 s = slot + glm::ivec3(dx, dy, dz);
        if (!world.slotInGrid(s)) continue;
        const size_t i = size_t(world.slotLinear(s));
        if (fn(first[i], first[i + 1])) return;
      }
}

}  // namespace

float faceLightLocalSum(const VoxelWorld& world, const glm::ivec3& slot) {
  float sum = 0.0f;
  forNearSlots(world, slot, [&](uint32_t begin, uint32_t end) {
    sum += cdfMass(world.emitters.cdf, begin, end);
    return false;
  });
  return sum;
}

int pickFaceLightEmitter(const VoxelWorld& world, const glm::ivec3& slot, float local_sum,
                         float u) {
  const EmitterList& list = world.emitters;
  const float a = shared::faceLightLocalShare(local_sum);
  if (!(u < a)) return list.pick((u - a) / (1.0f - a));
  const float v = u / a * local_sum;
  float acc = 0.0f, before = 0.0f;
  uint32_t begin = 0, end = 0;
  forNearSlots(world, slot, [&](uint32_t b, uint32_t e) {
    const float mass = cdfMass(list.cdf, b, e);
    if (!(mass > 0.0f)) return false;
    begin = b, end = e, before = acc;
    acc += mass;
    return v < acc;
  });
  const float target = (begin > 0 ? list.cdf[begin - 1] : 0.0f) + (v - before);
  const auto it = std::upper_bound(list.cdf.begin() + begin, list.cdf.begin() + end, target);
  return std::min(int(it - list.cdf.begin()), int(end) - 1);
}

glm::vec3 sampleEmittersAtFace(const VoxelWorld& world, const glm::ivec3& slot, float local_sum,
                               const glm::vec3& n, const glm::vec3& p, uint32_t key,
                               PathStats& stats) {
  const Emitter& e = world.emitters.emitters[size_t(pickFaceLightEmitter(
      world, slot, local_sum, shared::randomUniform(key, 0, shared::kDimEmitterChoice)))];
  const glm::vec3 point = shared::emitterFacePoint(
      e.voxel, e.face, shared::randomUniform(key, 0, shared::kDimEmitterPoint0),
      shared::randomUniform(key, 0, shared::kDimEmitterPoint1));
  const glm::vec3 to = point - p;
  const float dist2 = glm::dot(to, to);
  if (!(dist2 > 0.0f)) return glm::vec3(0.0f);
  const glm::vec3 l = to / std::sqrt(dist2);
  const float cos_l = glm::dot(n, l);
  const float cos_e = -glm::dot(glm::vec3(shared::faceNormal(e.face)), l);
  if (cos_l <= 0.0f || cos_e <= 0.0f) return glm::vec3(0.0f);
  glm::vec3 transmittance(1.0f);
  bool crossed = false;
  NoRecorder no_recorder;
  const TraceHit hit = traceShadow(world, p, l, transmittance, crossed, stats, no_recorder);
  if (!hit.hit || hit.voxel != e.voxel || hit.axis != e.face / 2) return glm::vec3(0.0f);
  const float pick =
      shared::faceLightPickFactor(local_sum, shared::slotsAdjacent(e.voxel >> 4, slot));
  const float pdf_e = emitterSolidAnglePdf(world, e.radiance, dist2, cos_e) * pick;
  if (!crossed) return shared::faceLightEmitterSample(e.radiance, cos_l, pdf_e);
  // Through glass only this estimator reaches the emitter (tracePath weighs the other 0).
  if (!(pdf_e > 0.0f) || !std::isfinite(pdf_e)) return glm::vec3(0.0f);
  return e.radiance * transmittance * (shared::faceLightDirectionPdf(cos_l) / pdf_e);
}

}  // namespace rdm::detail
