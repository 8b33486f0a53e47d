#include "rdm/trace/traversal.h"

#include "rdm/transport/rdm_shared_cpp.h"

namespace rdm {

float exactCentralDepth(const VoxelWorld& world, const glm::ivec3& origin, const glm::ivec3& dir,
                        std::vector<uint32_t>* slots) {
  ExactRay ray(origin, dir);
  ExactRay::Time t;
  int last = -1;
  TraceHit hit = traceVoxels(world, ray, t, [&](int slot) {
    if (slots && slot != last) slots->push_back(uint32_t(slot)), last = slot;
  });
  if (!hit.hit) return shared::kSkyDepth;
  if (hit.started_solid) return 0.0f;
  double length = std::sqrt(double(dir.x) * dir.x + double(dir.y) * dir.y + double(dir.z) * dir.z);
  return float(double(t.num) / double(t.den) * length / 16.0);
}

}  // namespace rdm
