// Path-traced reference images through a scene camera (docs/spec.md section 4's camera rays), with
// the bake's transport code and effect specialisation.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>

#include "rdm/base/status.h"
#include "rdm/image/image.h"
#include "rdm/scene/scene.h"
#include "rdm/scene/world.h"

namespace rdm {

struct RenderOptions {
  int width = 1280, height = 720;
  int spp = 64;
  int camera = 0;
  int threads = 0;  // 0: all cores
  std::function<void(int rows_done, int rows_total, uint64_t rays)> on_progress;
  const std::atomic<bool>* cancel = nullptr;  // set: stop between rows, return kCancelled
};

struct RenderReport {
  uint64_t rays = 0;
  double seconds = 0.0;
};

// The image plane of a W x H image at distance 1 in front of the camera: the ray through
// continuous pixel position (px, py) has direction forward + (2 px / W - 1) right +
// (1 - 2 py / H) up, normalised.
struct CameraPlane {
  glm::dvec3 forward, right, up;  // forward unit; right and up span the plane's half extents
};
CameraPlane cameraPlane(const Camera& camera, int width, int height);

// Direction (unit) of the ray through continuous pixel position (px, py) of a W x H image.
glm::vec3 cameraRayDirection(const Camera& camera, int width, int height, float px, float py);

// What renderReference refuses: a camera index out of range, a size or spp below 1.
Status checkRenderOptions(const Scene& scene, const RenderOptions& options);

// An RGB linear HDR image. Errors: camera index out of range.
Expected<Image> renderReference(const Scene& scene, const VoxelWorld& world,
                                const RenderOptions& options, RenderReport* report = nullptr);

}  // namespace rdm
