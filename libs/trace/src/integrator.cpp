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

}  // namespace rdm::detail
