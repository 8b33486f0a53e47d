#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "cli_app.h"
#include "commands.h"
#include "number_checks.h"
#include "output_check.h"
#include "progress.h"
#include "rdm/bake/render.h"
#include "rdm/image/exr_io.h"
#include "rdm/image/flip.h"
#include "rdm/image/png_io.h"
#include "rdm/image/tonemap.h"
#include "rdm/vulkan/vulkan_bake.h"
#include "scene_options.h"

namespace rdm::cli {
namespace {

// .exr: linear R, G, B; .png: Reinhard + sRGB, 8 bits.
Status writeImage(const std::string& path, const Image& image) {
  if (extensionOf(path) == "exr") return writeExr(path, image, kRgbChannels);
  Image mapped = tonemapReinhardSrgb(image);
  std::vector<uint8_t> bytes(mapped.pixels.size());
  for (size_t i = 0; i < bytes.size(); ++i)
    bytes[i] = uint8_t(std::lround(std::clamp(mapped.pixels[i], 0.0f, 1.0f) * 255.0f));
  return writePng(path, mapped.width, mapped.height, 3, bytes);
}

Expected<Image> renderOn(BakeBackend backend, const std::string& device, const Scene& scene,
                         const VoxelWorld& world, const RenderOptions& o, RenderReport& report) {
  if (backend == BakeBackend::kCpu) return renderReference(scene, world, o, &report);
  auto baker = VulkanBaker::create(device);
  if (!baker) return baker.status();
  return (*baker)->render(scene, world, o, &report);
}

}  // namespace

int cmdRender(const Args& args) {
  SceneArgs scene_args;
  RenderOptions o;
  o.spp = 64, o.width = 1280, o.height = 720;
  std::string out, backend_name = "auto", device, camera = "0";
  bool quiet = false;
  VerbApp app("render",
              "Path-trace a reference image through a scene camera, on the CPU or a Vulkan "
              "device. OUT.exr is linear HDR; OUT.png is Reinhard + sRGB tone-mapped.");
  addSceneOptions(app, scene_args, "");
  app.add_option("-o,--output", out, "output image, .exr or .png (checked before rendering)")
      ->required();
  app.add_option("--camera", camera, "scene camera: index or name")->type_name("INDEX|NAME");
  app.add_option("--spp", o.spp, "samples per pixel")->check(positiveCount());
  app.add_option("--width", o.width, "image width")->check(positiveCount());
  app.add_option("--height", o.height, "image height")->check(positiveCount());
  app.add_option("--threads", o.threads, "CPU threads (0: all cores)")
      ->check(countOrZero("all cores"));
  app.add_option("--backend", backend_name,
                 "cpu, vulkan, or auto (Vulkan on a GPU, else the CPU; lavapipe is slower than "
                 "the CPU on the same cores)");
  app.add_option("--device", device, "Vulkan device: index or name substring")
      ->default_str("first GPU");
  app.add_flag("-q,--quiet", quiet, "no progress");
  if (auto code = parseArgs(app, args)) return *code;
  auto backend = parseBakeBackend(backend_name);
  if (!backend) return fail("render", backend.error(), 2);
  if (*backend == BakeBackend::kCpu && !device.empty())
    return fail("render", "--device names a Vulkan device; it needs --backend vulkan or auto", 2);
  const std::string ext = extensionOf(out);
  if (ext != "exr" && ext != "png") {
    return fail(
        "render",
        out + ": unknown image format '." + ext + "'; use .exr (linear HDR) or .png (tone-mapped)",
        2);
  }
  if (Status s = checkSceneArgs(scene_args); !s) return fail("render", s.message(), 2);
  auto scene = sceneFromArgs(scene_args);
  if (!scene) return fail("render", scene.error());
  auto camera_index = findCamera(*scene, camera);
  if (!camera_index) return fail("render", camera_index.error());
  o.camera = int(*camera_index);
  if (Status s = checkOutputFile(out); !s) return fail("render", s.message());
  ProgressReporter progress("rows");
  if (!quiet) {
    auto t0 = std::chrono::steady_clock::now();
    o.on_progress = [&, t0](int done, int total, uint64_t rays) {
      progress.update(done, total, done, total, rays,
                      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    };
  }
  VoxelWorld world = buildWorld(*scene);
  const BackendChoice choice = resolveBakeBackend(*backend, device, *scene);
  if (!quiet && *backend == BakeBackend::kAuto) std::printf("backend: %s\n", choice.reason.c_str());
  RenderReport report;
  auto image = renderOn(choice.backend, device, *scene, world, o, report);
  progress.finish();
  if (!image) return fail("render", image.error());
  if (Status s = writeImage(out, *image); !s) return fail("render", s.message());
  std::printf("rendered %dx%d at %d spp in %.2f s (%srays/s) -> %s\n", o.width, o.height, o.spp,
              report.seconds,
              formatCount(report.seconds > 0 ? double(report.rays) / report.seconds : 0).c_str(),
              out.c_str());
  return 0;
}

}  // namespace rdm::cli
