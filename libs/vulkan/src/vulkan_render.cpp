// Reference renders on the bake kernel (rdm render --backend vulkan; docs/vulkan.md "Reference
// renders"): one camera job per pixel (kJobCameraLevel, rdm_gpu_layout.h), spp samples each,
// with rdm::renderReference's path keys and pixel jitter. The host sums each pixel's samples
// in sample order in double and divides by spp, as the CPU does, so the two images differ by
// the kernel's float arithmetic only (the ray direction is formed in float on the device).
#if RDM_HAVE_VULKAN

#include <algorithm>
#include <chrono>

#include "rdm/bake/rdm_list.h"
#include "rdm/bake/render.h"
#include "vulkan_context.h"
#include "vulkan_kernel_run.h"

namespace rdm::vkbake {
namespace {

gpu::GpuCamera gpuCamera(const Camera& camera, int width, int height) {
  const CameraPlane plane = cameraPlane(camera, width, height);
  gpu::GpuCamera c;
  c.origin = glm::vec4(glm::vec3(camera.position * 16.0), float(width));
  c.forward = glm::vec4(glm::vec3(plane.forward), float(height));
  c.right = glm::vec4(glm::vec3(plane.right), 0.0f);
  c.up = glm::vec4(glm::vec3(plane.up), 0.0f);
  return c;
}

// The mean of each pixel of [first, first + count) over its spp samples, in sample order.
class PixelSums {
 public:
  PixelSums(uint32_t first, uint32_t count) : first_(first), sums_(count, glm::dvec3(0.0)) {}

  void add(const glm::vec4* values, uint32_t samples) {
    for (size_t p = 0; p < sums_.size(); ++p) {
      for (uint32_t s = 0; s < samples; ++s) {
        const glm::vec4& v = values[p * samples + s];
        checkPathResult(v);
        sums_[p] += glm::dvec3(glm::vec3(v));
      }
    }
  }

  void store(Image& image, int spp) const {
    for (size_t p = 0; p < sums_.size(); ++p) {
      const int pixel = int(first_ + p);
      const glm::dvec3 mean = sums_[p] / double(spp);
      for (int c = 0; c < 3; ++c)
        image.at(pixel % image.width, pixel / image.width, c) = float(mean[c]);
    }
  }

 private:
  const uint32_t first_;
  std::vector<glm::dvec3> sums_;
};

}  // namespace

Expected<Image> renderOnContext(Context& ctx, const Scene& scene, const VoxelWorld& world,
                                const RenderOptions& o, RenderReport* report) {
  const auto start = std::chrono::steady_clock::now();
  const EffectSet effects = sceneEffects(world);
  KernelConfig config;
  config.sun = effects.sun, config.emitters = effects.emitters;
  config.spp = uint32_t(o.spp);
  config.camera = gpuCamera(scene.cameras[size_t(o.camera)], o.width, o.height);
  auto created = KernelRun::create(ctx, world, scene.bake, config);
  if (!created) return created.status();
  KernelRun& kernel = **created;
  const uint32_t pixels = uint32_t(o.width) * uint32_t(o.height);
  Image image(o.width, o.height, 3);
  uint32_t done = 0;
  auto tick = [&] {
    if (o.on_progress) o.on_progress(int(done / uint32_t(o.width)), o.height, kernel.rays());
  };
  while (done < pixels) {
    // A group's jobs stay at most maxJobs() of its start, so every batch of it fits the buffers.
    const uint32_t count = std::min(kernel.maxJobs(), pixels - done);
    PixelSums sums(done, count);
    for (uint32_t s0 = 0; s0 < uint32_t(o.spp);) {
      const uint32_t samples = kernel.samplesFrom(s0);
      for (uint32_t p = 0; p < count; ++p)
        kernel.jobs()[p].data = glm::uvec4(uint32_t(o.camera), gpu::kJobCameraLevel, done + p, 0u);
      auto ran = kernel.runBatch(count, samples, s0, o.cancel, tick);
      if (!ran) return ran.status();
      if (!*ran) return Status::error(StatusCode::kCancelled, "render cancelled");
      sums.add(kernel.results(), samples);
      s0 += samples;
    }
    sums.store(image, o.spp);
    done += count;
    tick();
  }
  if (report) {
    report->rays = kernel.rays();
    report->seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  return image;
}

}  // namespace rdm::vkbake

#endif  // RDM_HAVE_VULKAN
