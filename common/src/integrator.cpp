#include "rdm/integrator.h"

namespace rdm::detail {

float emitterSolidAnglePdf(const VoxelWorld& world, const glm::vec3& radiance, float dist2,
                           float cos_e) {
  if (!(cos_e > 0.0f) || world.emitters.total_luminance <= 0.0f) return 0.0f;
  float pick = std::max(luminance(radiance), 1e-20f) / world.emitters.total_luminance;
  return pick * dist2 / cos_e;  // emitter faces have unit area in voxel units
}

EmitterPoint pickEmitterPoint(const VoxelWorld& world, uint32_t key, uint32_t bounce) {
  const EmitterList& list = world.emitters;
  const Emitter& e =
      list.emitters[list.pick(shared::randomUniform(key, bounce, shared::kDimEmitterChoice))];
  const int axis = e.face / 2;
  glm::vec3 q = glm::vec3(e.voxel);
  q[axis] += e.face % 2 == 0 ? 1.0f : 0.0f;
  q[(axis + 1) % 3] += shared::randomUniform(key, bounce, shared::kDimEmitterPoint0);
  q[(axis + 2) % 3] += shared::randomUniform(key, bounce, shared::kDimEmitterPoint1);
  return {&e, q};
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
