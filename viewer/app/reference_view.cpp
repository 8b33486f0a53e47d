#include "reference_view.h"

#include <chrono>
#include <exception>

#include "rdm/bake/render.h"
#include "rdm/base/thread_priority.h"
#include "rdm/image/flip.h"
#include "rdm/image/tonemap.h"

namespace rdm::viewer {
namespace {

Image8 toImage8(const Image& srgb) {
  Image8 out{srgb.width, srgb.height, 3,
             std::vector<uint8_t>(size_t(srgb.width) * srgb.height * 3)};
  for (int y = 0; y < srgb.height; ++y)
    for (int x = 0; x < srgb.width; ++x)
      for (int c = 0; c < 3; ++c) {
        const float v = std::clamp(srgb.at(x, y, c), 0.0f, 1.0f);
        out.pixels[(size_t(y) * srgb.width + x) * 3 + c] = uint8_t(v * 255.0f + 0.5f);
      }
  return out;
}

Image toImage(const Image8& ldr) {
  Image out(ldr.width, ldr.height, 3);
  for (int y = 0; y < ldr.height; ++y)
    for (int x = 0; x < ldr.width; ++x)
      for (int c = 0; c < 3; ++c)
        out.at(x, y, c) = ldr.pixels[(size_t(y) * ldr.width + x) * ldr.channels + c] / 255.0f;
  return out;
}

Expected<ReferenceImage> renderView(Scene scene, const Camera& camera, RenderOptions options) {
  scene.cameras.push_back(camera);
  options.camera = int(scene.cameras.size()) - 1;
  const VoxelWorld world = buildWorld(scene);
  RenderReport report;
  auto linear = renderReference(scene, world, options, &report);
  if (!linear) return linear.status();
  ReferenceImage out{camera, std::move(*linear), {}, options.spp, report.seconds};
  out.ldr = toImage8(tonemapReinhardSrgb(out.linear));
  return out;
}

}  // namespace

ReferenceRender::~ReferenceRender() {
  stop();
}

void ReferenceRender::stop() {
  cancel_ = true;
  if (worker_.joinable()) worker_.join();
  cancel_ = false;
}

void ReferenceRender::start(const Scene& scene, const Camera& camera, int width, int height,
                            int spp) {
  stop();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    result_.reset();
  }
  rows_done_ = 0, rows_total_ = height, busy_ = true;
  RenderOptions options;
  options.width = width, options.height = height, options.spp = spp;
  options.cancel = &cancel_;
  options.on_progress = [this](int rows_done, int, uint64_t) { rows_done_ = rows_done; };
  worker_ = std::thread([this, scene, camera, options] {
    lowerThreadPriority();  // the window's frames come first
    Expected<ReferenceImage> result = Status::error("reference render failed");
    try {
      result = renderView(scene, camera, options);
    } catch (const std::exception& e) {
      result = Status::error(std::string("reference render failed: ") + e.what());
    }
    std::lock_guard<std::mutex> lock(mutex_);
    if (!cancel_) result_ = std::move(result);
    busy_ = false;
  });
}

double ReferenceRender::fraction() const {
  return double(rows_done_.load()) / double(std::max(1, rows_total_.load()));
}

std::optional<Expected<ReferenceImage>> ReferenceRender::take() {
  std::lock_guard<std::mutex> lock(mutex_);
  return std::exchange(result_, std::nullopt);
}

Expected<ReferenceComparison> compareWithReference(const Image8& reference, const Image8& shown) {
  if (reference.width != shown.width || reference.height != shown.height)
    return Status::invalid("size", "the window was resized since the reference was started");
  FlipResult flip = computeLdrFlip(toImage(reference), toImage(shown));
  return ReferenceComparison{flip.mean, magmaColorMap(flip.error_map)};
}

}  // namespace rdm::viewer
