#include <chrono>
#include <cstdio>

#include "args.h"
#include "commands.h"
#include "progress.h"
#include "rdm/exr_io.h"
#include "rdm/render.h"
#include "rdm/vulkan_bake.h"
#include "scene_options.h"

namespace rdm::cli {

int cmdRender(const Args& args) {
  std::set<std::string> values = kSceneValueOptions;
  values.insert({"-o", "--output", "--camera", "--width", "--height", "--backend", "--device"});
  ArgParser parser(values, {"--help", "--quiet"});
  std::string e = parser.parse(args);
  auto out = parser.value("-o") ? parser.value("-o") : parser.value("--output");
  if (!e.empty() || parser.flag("--help") || !out) {
    std::fprintf(
        stderr,
        "%susage: rdm render (SCENE.json | --scene NAME) [--camera N] [--spp N] [--width W] "
        "[--height H]\n"
        "                  [--threads N] [--backend cpu|auto] -o OUT.exr\n"
        "  reference renders run on the CPU (--backend vulkan is refused; rdm bake has it)\n",
        e.empty() ? "" : ("rdm render: " + e + "\n").c_str());
    return parser.flag("--help") ? 0 : 2;
  }
  auto backend = parseBakeBackend(parser.value("--backend").value_or("auto"));
  if (!backend) return std::fprintf(stderr, "rdm render: %s\n", backend.error().c_str()), 2;
  if (*backend == BakeBackend::kVulkan || parser.value("--device")) {
    return std::fprintf(
               stderr,
               "rdm render: reference renders run on the CPU only; the Vulkan backend bakes RDMs "
               "(rdm bake --backend vulkan). Use --backend cpu or auto, without --device.\n"),
           2;
  }
  auto scene = sceneFromArgs(parser);
  if (!scene) return std::fprintf(stderr, "rdm render: %s\n", scene.error().c_str()), 1;
  RenderOptions o;
  std::string error;
  o.camera = int(parser.integer("--camera", error).value_or(0));
  o.spp = int(parser.integer("--spp", error).value_or(64));
  o.width = int(parser.integer("--width", error).value_or(1280));
  o.height = int(parser.integer("--height", error).value_or(720));
  o.threads = int(parser.integer("--threads", error).value_or(0));
  if (!error.empty()) return std::fprintf(stderr, "rdm render: %s\n", error.c_str()), 2;
  ProgressReporter progress("rows");
  if (!parser.flag("--quiet")) {
    auto t0 = std::chrono::steady_clock::now();
    o.on_progress = [&, t0](int done, int total, uint64_t rays) {
      progress.update(done, total, rays,
                      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    };
  }
  VoxelWorld world = buildWorld(*scene);
  RenderReport report;
  auto image = renderReference(*scene, world, o, &report);
  progress.finish();
  if (!image) return std::fprintf(stderr, "rdm render: %s\n", image.error().c_str()), 1;
  if (Status s = writeExr(*out, *image, {"R", "G", "B"}); !s)
    return std::fprintf(stderr, "rdm render: %s\n", s.message().c_str()), 1;
  std::printf("rendered %dx%d at %d spp in %.2f s (%srays/s) -> %s\n", o.width, o.height, o.spp,
              report.seconds,
              formatCount(report.seconds > 0 ? report.rays / report.seconds : 0).c_str(),
              out->c_str());
  return 0;
}

}  // namespace rdm::cli
