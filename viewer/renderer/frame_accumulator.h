// Anti-aliasing by accumulation while the view is still: successive frames shade at
// sub-pixel offsets and average into one image, a box filter over each pixel as the
// path-traced reference (`rdm render`) samples it. Anything that shapes the image (camera,
// terms, resolution divisor, scene, atlas, size) starts the average again.
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "rdm/scene/scene.h"

namespace rdm::viewer {

// Offset of frame k's sample from the pixel centre, in pixels, within [-0.5, 0.5)^2: the
// centre for k = 0 (so a single frame is the unjittered one), then the Halton (2, 3) points.
glm::vec2 pixelJitter(int k);

struct AccumulationStep {
  bool shade = true;  // false: the average is complete; the frame only re-presents it
  glm::vec2 jitter{0.0f};
  float weight = 1.0f;  // of this frame in the running mean: 1 / (frames averaged + 1)
};

class FrameAccumulator {
 public:
  // Frames averaged at most; 1 (the default) shades every frame afresh at pixel centres.
  void setLimit(int frames);
  // The image's content changed (scene, atlas, size): the next frame starts a new average.
  void invalidate() { valid_ = false; }
  // The step for a frame of `camera` with `terms` at resolution `divisor`; a divisor above
  // 1 (interactive resolution) never accumulates.
  AccumulationStep next(const Camera& camera, uint32_t terms, int divisor);
  // Frames in the current average.
  int frames() const { return frames_; }
  // More frames would still refine the image.
  bool refining() const { return limit_ > 1 && divisor_ == 1 && frames_ < limit_; }

 private:
  int limit_ = 1, frames_ = 0;
  bool valid_ = false;
  Camera camera_;
  uint32_t terms_ = 0;
  int divisor_ = 1;
};

}  // namespace rdm::viewer
