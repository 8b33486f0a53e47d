#include "frame_accumulator.h"

#include "rdm/base/check.h"
#include "rdm/transport/sobol.h"

namespace rdm::viewer {

glm::vec2 pixelJitter(int k) {
  if (k == 0) return glm::vec2(0.0f);
  return glm::vec2(radicalInverse2(uint32_t(k)), radicalInverse(3, uint32_t(k))) - 0.5f;
}

void FrameAccumulator::setLimit(int frames) {
  RDM_CHECK(frames >= 1);
  limit_ = frames;
  valid_ = false;
}

AccumulationStep FrameAccumulator::next(const Camera& camera, uint32_t terms, int divisor) {
  const bool same = valid_ && camera == camera_ && terms == terms_ && divisor == divisor_;
  if (!same || limit_ == 1 || divisor > 1) frames_ = 0;
  valid_ = true, camera_ = camera, terms_ = terms, divisor_ = divisor;
  if (frames_ >= limit_) return {false, glm::vec2(0.0f), 0.0f};
  const AccumulationStep step{true, pixelJitter(frames_), 1.0f / float(frames_ + 1)};
  ++frames_;
  return step;
}

}  // namespace rdm::viewer
