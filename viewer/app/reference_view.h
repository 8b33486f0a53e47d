// "Path-trace this view" (docs/viewer.md, "Reference of the view"): the CPU reference renderer
// (rdm/bake/render.h, the bake's own transport) for the window's current view, on a worker
// thread. Once done the window shows it in its right half beside the real-time image, with
// the LDR-FLIP between the two (the real-time image read back at the same size).
#pragma once

#include <atomic>
#include <mutex>
#include <optional>
#include <thread>

#include "rdm/base/status.h"
#include "rdm/image/image.h"
#include "rdm/scene/scene.h"

namespace rdm::viewer {

struct ReferenceImage {
  Camera camera;  // the view it was rendered for
  Image linear;   // RGB radiance
  Image8 ldr;     // RGB, Reinhard + sRGB, as the real-time image's tone map
  int spp = 0;
  double seconds = 0.0;
};

class ReferenceRender {
 public:
  ReferenceRender() = default;
  ReferenceRender(const ReferenceRender&) = delete;
  ReferenceRender& operator=(const ReferenceRender&) = delete;
  ~ReferenceRender();  // cancels a render in flight and joins it

  // Renders `scene` through `camera` at width x height and `spp`, on all cores at the
  // worker's lowered priority; a render in flight is cancelled first.
  void start(const Scene& scene, const Camera& camera, int width, int height, int spp);
  bool busy() const { return busy_.load(); }
  double fraction() const;  // rows done / rows, while busy
  // The finished render (or why it failed), handed out once.
  std::optional<Expected<ReferenceImage>> take();

 private:
  void stop();
  std::thread worker_;
  std::atomic<bool> cancel_{false}, busy_{false};
  std::atomic<int> rows_done_{0}, rows_total_{1};
  std::mutex mutex_;
  std::optional<Expected<ReferenceImage>> result_;  // under mutex_
};

// The LDR-FLIP of the real-time image `shown` against the reference, both RGB 8-bit sRGB of
// the same size; its per-pixel map in magma colours for display.
struct ReferenceComparison {
  double ldr_flip = 0.0;
  Image8 flip_map;
};
Expected<ReferenceComparison> compareWithReference(const Image8& reference, const Image8& shown);

}  // namespace rdm::viewer
