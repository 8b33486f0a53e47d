#include "rdm/bake/render.h"

#include <atomic>
#include <chrono>
#include <cmath>
#include <numbers>

#include "rdm/bake/bake.h"
#include "rdm/base/parallel.h"
#include "rdm/trace/integrator.h"

namespace rdm {
namespace {

using RowFn = void (*)(const VoxelWorld&, const Scene&, const RenderOptions&, int row, Image&,
                       PathStats&);

// The camera ray of pixel (x, y), sample s, and its path key.
struct CameraSample {
  glm::vec3 dir;
  uint32_t key;
};
CameraSample cameraSample(const Scene& scene, const RenderOptions& o, int x, int y, int s) {
  const uint32_t pixel = uint32_t(y * o.width + x);
  const uint32_t key = shared::pathKey(scene.bake.seed, uint32_t(o.camera), 0u, pixel, uint32_t(s));
  const float px = float(x) + shared::randomUniform(key, 0, shared::kDimOrigin0);
  const float py = float(y) + shared::randomUniform(key, 0, shared::kDimOrigin1);
  return {cameraRayDirection(scene.cameras[o.camera], o.width, o.height, px, py), key};
}

// A row's camera rays go through the voxel stream first, as one batch; each path then starts
// from its first hit.
template <bool kSun, bool kEmitters>
void renderRow(const VoxelWorld& world, const Scene& scene, const RenderOptions& o, int y,
               Image& image, PathStats& stats) {
  const glm::vec3 origin = glm::vec3(scene.cameras[o.camera].position * 16.0);
  FirstSegments first;
  for (int x = 0; x < o.width; ++x) {
    for (int s = 0; s < o.spp; ++s) first.add(origin, cameraSample(scene, o, x, y, s).dir);
  }
  first.trace(world);
  for (int x = 0; x < o.width; ++x) {
    glm::dvec3 sum(0.0);
    for (int s = 0; s < o.spp; ++s) {
      const CameraSample c = cameraSample(scene, o, x, y, s);
      sum += glm::dvec3(tracePath<kSun, kEmitters>(world, scene.bake.max_bounces, origin, c.dir,
                                                   c.key, PathOrigin::kCamera, stats, NoRecorder(),
                                                   first.take(origin, c.dir)));
    }
    for (int c = 0; c < 3; ++c) image.at(x, y, c) = float(sum[c] / o.spp);
  }
}

RowFn selectRowKernel(const EffectSet& e) {
  if (e.sun && e.emitters) return renderRow<true, true>;
  if (e.sun) return renderRow<true, false>;
  if (e.emitters) return renderRow<false, true>;
  return renderRow<false, false>;
}

}  // namespace

CameraPlane cameraPlane(const Camera& camera, int width, int height) {
  const glm::dvec3 forward = glm::normalize(camera.target - camera.position);
  const glm::dvec3 right = glm::normalize(glm::cross(forward, glm::dvec3(0.0, 1.0, 0.0)));
  const glm::dvec3 up = glm::cross(right, forward);
  const double tan_half = std::tan(camera.fov_deg * std::numbers::pi / 360.0);
  return {forward, right * (tan_half * width / height), up * tan_half};
}

glm::vec3 cameraRayDirection(const Camera& camera, int width, int height, float px, float py) {
  const CameraPlane plane = cameraPlane(camera, width, height);
  const double a = 2.0 * px / width - 1.0;
  const double b = 1.0 - 2.0 * py / height;
  return glm::vec3(glm::normalize(plane.forward + a * plane.right + b * plane.up));
}

Status checkRenderOptions(const Scene& scene, const RenderOptions& o) {
  if (o.camera < 0 || o.camera >= int(scene.cameras.size())) {
    return Status::error("camera " + std::to_string(o.camera) + " out of range: the scene has " +
                         std::to_string(scene.cameras.size()) + " cameras");
  }
  if (o.width < 1 || o.height < 1 || o.spp < 1)
    return Status::error("image size and spp must be positive");
  return {};
}

Expected<Image> renderReference(const Scene& scene, const VoxelWorld& world, const RenderOptions& o,
                                RenderReport* report) {
  if (Status s = checkRenderOptions(scene, o); !s) return s;
  auto start = std::chrono::steady_clock::now();
  Image image(o.width, o.height, 3);
  const RowFn kernel = selectRowKernel(sceneEffects(world));
  std::atomic<int> done{0};
  std::atomic<uint64_t> rays{0};
  ParallelOptions parallel;
  parallel.threads = o.threads;
  if (o.on_progress) parallel.on_tick = [&] { o.on_progress(done.load(), o.height, rays.load()); };
  parallelFor(size_t(o.height), parallel, [&](size_t y) {
    if (o.cancel && o.cancel->load()) return false;
    PathStats stats;
    kernel(world, scene, o, int(y), image, stats);
    rays += stats.rays;
    ++done;
    return true;
  });
  if (o.cancel && o.cancel->load())
    return Status::error(StatusCode::kCancelled, "render cancelled");
  if (report) {
    report->rays = rays.load();
    report->seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  return image;
}

}  // namespace rdm
