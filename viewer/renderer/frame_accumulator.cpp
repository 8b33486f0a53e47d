#include "frame_accumulator.h"

#include "rdm/check.h"

namespace rdm::viewer {
namespace {

float radicalInverse(int base, int k) {
  float inverse = 1.0f / float(base), scale = inverse, result = 0.0f;
  for (; k > 0; k /= base, scale *= inverse) result += float(k % base) * scale;
  return result;
}

}  // namespace

glm::vec2 pixelJitter(int k) {
  if (k == 0) return glm::vec2(0.0f);
  return glm::vec2(radicalInverse(2, k), radicalInverse(3, k)) - 0.5f;
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
