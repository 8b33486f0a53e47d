#include "rdm/trace/integrator.h"

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
                              float cos_e, const TraceHit& hit) {
  if (!hit.hit || hit.voxel != e.emitter->voxel || hit.axis != e.emitter->face / 2)
    return glm::vec3(0.0f);
  float pdf_e = emitterSolidAnglePdf(world, e.emitter->radiance, dist2, cos_e);
  if (!(pdf_e > 0.0f) || !std::isfinite(pdf_e)) return glm::vec3(0.0f);
  float w = powerHeuristic(pdf_e, pdfBsdf(m, v_local, l_local));
  return evalBsdf(m, v_local, l_local) * e.emitter->radiance * (l_local.z * w / pdf_e);
}

glm::vec3 sampleEmittersAtFace(const VoxelWorld& world, const glm::vec3& n, const glm::vec3& p,
                               uint32_t key, PathStats& stats) {
  const EmitterPoint e = pickEmitterPoint(world, key, 0);
  const glm::vec3 to = e.point - p;
  const float dist2 = glm::dot(to, to);
  if (!(dist2 > 0.0f)) return glm::vec3(0.0f);
  const glm::vec3 l = to / std::sqrt(dist2);
  const float cos_l = glm::dot(n, l);
  const float cos_e = -glm::dot(glm::vec3(shared::faceNormal(e.emitter->face)), l);
  if (cos_l <= 0.0f || cos_e <= 0.0f) return glm::vec3(0.0f);
  float t;
  ++stats.rays;
  const TraceHit hit = traceVoxels(world, FloatRay(p, l), t);
  if (!hit.hit || hit.voxel != e.emitter->voxel || hit.axis != e.emitter->face / 2)
    return glm::vec3(0.0f);
  return shared::faceLightEmitterSample(
      e.emitter->radiance, cos_l, emitterSolidAnglePdf(world, e.emitter->radiance, dist2, cos_e));
}

}  // namespace rdm::detail
