#include "rdm/integrator.h"

namespace rdm::detail {

float emitterSolidAnglePdf(const VoxelWorld& world, const glm::vec3& radiance, float dist2, float cos_e) {
  if (!(cos_e > 0.0f) || world.emitters.total_luminance <= 0.0f) return 0.0f;
  float pick = std::max(luminance(radiance), 1e-20f) / world.emitters.total_luminance;
  return pick * dist2 / cos_e;  // emitter faces have unit area in voxel units
}

glm::vec3 sampleEmitters(const VoxelWorld& world, const Material& m, const Frame& frame, const glm::vec3& v_local,
                         const glm::vec3& p, uint32_t key, uint32_t bounce, PathStats& stats) {
  const EmitterList& list = world.emitters;
  const Emitter& e = list.emitters[list.pick(shared::randomUniform(key, bounce, shared::kDimEmitterChoice))];
  const int axis = e.face / 2;
  glm::vec3 q = glm::vec3(e.voxel);
  q[axis] += e.face % 2 == 0 ? 1.0f : 0.0f;
  q[(axis + 1) % 3] += shared::randomUniform(key, bounce, shared::kDimEmitterPoint0);
  q[(axis + 2) % 3] += shared::randomUniform(key, bounce, shared::kDimEmitterPoint1);
  glm::vec3 to = q - p;
  float dist2 = glm::dot(to, to);
  if (!(dist2 > 0.0f)) return glm::vec3(0.0f);
  glm::vec3 l = to / std::sqrt(dist2);
  glm::vec3 l_local = frame.toLocal(l);
  float cos_e = -glm::dot(glm::vec3(shared::faceNormal(e.face)), l);
  if (l_local.z <= 0.0f || cos_e <= 0.0f) return glm::vec3(0.0f);
  glm::vec3 f = evalBsdf(m, v_local, l_local);
  if (f == glm::vec3(0.0f)) return glm::vec3(0.0f);
  float t;
  ++stats.rays;
  TraceHit hit = traceVoxels(world, FloatRay(p, l), t);
  if (!hit.hit || hit.voxel != e.voxel || hit.axis != axis) return glm::vec3(0.0f);
  float pdf_e = emitterSolidAnglePdf(world, e.radiance, dist2, cos_e);
  if (!(pdf_e > 0.0f) || !std::isfinite(pdf_e)) return glm::vec3(0.0f);
  float w = powerHeuristic(pdf_e, pdfBsdf(m, v_local, l_local));
  return f * e.radiance * (l_local.z * w / pdf_e);
}

}  // namespace rdm::detail
