// The first segments of a batch of paths, traced ahead as one stream (traceVoxelStream, a SIMD
// lane per ray) and handed to tracePath in the order the paths are then traced. A path whose
// ray is not the next one of the batch traces its first segment itself, so a batch that
// misses a path costs time, never a different result: the stream's hits are traceVoxels'.
#pragma once

#include <vector>

#include <glm/glm.hpp>

#include "rdm/trace/traversal.h"

namespace rdm {

struct FirstSegment {
  TraceHit hit;
  float t = 0.0f;
};

class FirstSegments {
 public:
  void clear();
  void add(const glm::vec3& origin, const glm::vec3& dir);
  // Traces every ray added since clear().
  void trace(const VoxelWorld& world);
  // The next segment when its ray is (origin, dir), bit for bit; else nullptr.
  const FirstSegment* take(const glm::vec3& origin, const glm::vec3& dir);

 private:
  std::vector<FloatRay> rays_;
  std::vector<TraceHit> hits_;
  std::vector<float> t_;
  std::vector<FirstSegment> segments_;
  size_t next_ = 0;
};

}  // namespace rdm
