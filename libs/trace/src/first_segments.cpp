#include "rdm/trace/first_segments.h"

#include <cstring>

#include "rdm/trace/voxel_stream.h"

namespace rdm {

void FirstSegments::clear() {
  rays_.clear(), segments_.clear();
  next_ = 0;
}

void FirstSegments::add(const glm::vec3& origin, const glm::vec3& dir) {
  rays_.emplace_back(origin, dir);
}

void FirstSegments::trace(const VoxelWorld& world) {
  hits_.resize(rays_.size()), t_.assign(rays_.size(), 0.0f);
  traceVoxelStream(world, rays_, hits_, t_);
  segments_.resize(rays_.size());
  for (size_t i = 0; i < rays_.size(); ++i) segments_[i] = {hits_[i], t_[i]};
  next_ = 0;
}

const FirstSegment* FirstSegments::take(const glm::vec3& origin, const glm::vec3& dir) {
  if (next_ >= segments_.size()) return nullptr;
  const FloatRay& ray = rays_[next_];
  if (std::memcmp(&ray.o, &origin, sizeof(origin)) != 0 ||
      std::memcmp(&ray.d, &dir, sizeof(dir)) != 0)
    return nullptr;
  return &segments_[next_++];
}

}  // namespace rdm
