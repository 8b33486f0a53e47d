#include <cstdio>
#include <fstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "args.h"
#include "commands.h"
#include "progress.h"
#include "rdm/atlas.h"
#include "rdm/bake.h"
#include "rdm/file_util.h"
#include "rdm/shard.h"
#include "rdm/vulkan_bake.h"
#include "scene_options.h"

namespace rdm::cli {
namespace {

constexpr const char* kUsage =
    "usage: rdm bake (SCENE.json | --scene NAME) -o DIR [--spp N] [--max-hemisphere S]\n"
    "                [--max-bounces N] [--seed N] [--threads N] [--target-error E] [--shard I/N]\n"
    "                [--backend cpu|vulkan|auto] [--device NAME|INDEX]\n"
    "  --backend: where the bake runs (default auto: a Vulkan GPU if one exists, else the CPU;\n"
    "             docs/vulkan.md). --device picks the Vulkan device by index or name.\n";

nlohmann::json reportJson(const BakeReport& r, const AtlasLayout* layout, const Scene& scene,
                          int threads, const std::string& backend, const std::string& device) {
  nlohmann::json j = {{"rdms", r.rdms},
                      {"texels", r.texels},
                      {"rays", r.rays},
                      {"seconds", r.seconds},
                      {"rays_per_second", r.seconds > 0 ? double(r.rays) / r.seconds : 0.0},
                      {"threads", threads},
                      {"backend", backend},
                      {"device", device},
                      {"faces_baked", r.faces_baked},
                      {"faces_skipped", r.faces_skipped},
                      {"spp", scene.bake.spp},
                      {"max_hemisphere", scene.bake.max_hemisphere},
                      {"max_bounces", scene.bake.max_bounces},
                      {"mean_relative_error", r.mean_relative_error},
                      {"max_relative_error", r.max_relative_error},
                      {"effects_simulated", r.effects.describeSimulated()},
                      {"effects_skipped", r.effects.describeSkipped()}};
  if (layout) {
    j["occupancy"] = layout->occupancy();
    j["pages"] = layout->pages.size();
  }
  return j;
}

void printSummary(const BakeReport& r, const AtlasLayout* layout, const Scene& scene) {
  std::printf("RDMs:      %d (faces baked %d, skipped %d)\n", r.rdms, r.faces_baked,
              r.faces_skipped);
  std::printf("texels:    %stexels   rays: %srays\n", formatCount(double(r.texels)).c_str(),
              formatCount(double(r.rays)).c_str());
  std::printf("time:      %.2f s (%srays/s)\n", r.seconds,
              formatCount(r.seconds > 0 ? r.rays / r.seconds : 0).c_str());
  if (layout && !layout->pages.empty()) {
    std::printf("atlas:     %zu page(s), page 0 %dx%d, occupancy %.2f %%\n", layout->pages.size(),
                layout->pages[0].width, layout->pages[0].height, 100.0 * layout->occupancy());
  }
  std::printf("simulated: %s\n", r.effects.describeSimulated().c_str());
  std::printf("skipped:   %s\n", r.effects.describeSkipped().c_str());
  std::printf("noise:     mean relative standard error %.2f %% (max %.1f %%) at %d spp, S <= %d\n",
              100.0 * r.mean_relative_error, 100.0 * r.max_relative_error, scene.bake.spp,
              scene.bake.max_hemisphere);
}

bool parseShard(const std::string& text, int& index, int& count) {
  return std::sscanf(text.c_str(), "%d/%d", &index, &count) == 2 && count >= 1 && index >= 0 &&
         index < count;
}

}  // namespace

int cmdBake(const Args& args) {
  std::set<std::string> values = kSceneValueOptions;
  values.insert(
      {"-o", "--output", "--target-error", "--shard", "--max-spp-factor", "--backend", "--device"});
  ArgParser parser(values, {"--help", "--quiet"});
  if (std::string e = parser.parse(args); !e.empty() || parser.flag("--help")) {
    std::fprintf(stderr, "%s%s", e.empty() ? "" : ("rdm bake: " + e + "\n").c_str(), kUsage);
    return e.empty() ? 0 : 2;
  }
  auto out = parser.value("-o") ? parser.value("-o") : parser.value("--output");
  if (!out) return std::fprintf(stderr, "rdm bake: -o DIR is required\n%s", kUsage), 2;
  auto scene = sceneFromArgs(parser);
  if (!scene) return std::fprintf(stderr, "rdm bake: %s\n", scene.error().c_str()), 1;
  BakeOptions options;
  std::string error;
  options.threads = int(parser.integer("--threads", error).value_or(0));
  options.target_error = parser.number("--target-error", error).value_or(0.0);
  options.max_spp_factor = int(parser.integer("--max-spp-factor", error).value_or(16));
  if (auto shard = parser.value("--shard");
      shard && !parseShard(*shard, options.shard_index, options.shard_count)) {
    error = "--shard expects I/N with 0 <= I < N, got '" + *shard + "'";
  }
  if (options.threads < 0 || options.target_error < 0 || options.max_spp_factor < 1)
    error = "negative option value";
  if (!error.empty()) return std::fprintf(stderr, "rdm bake: %s\n", error.c_str()), 2;
  auto requested = parseBakeBackend(parser.value("--backend").value_or("auto"));
  if (!requested) return std::fprintf(stderr, "rdm bake: %s\n", requested.error().c_str()), 2;
  const std::string device = parser.value("--device").value_or("");
  if (!device.empty() && *requested == BakeBackend::kCpu) {
    return std::fprintf(
               stderr,
               "rdm bake: --device selects a Vulkan device; it does not apply to --backend cpu\n"),
           2;
  }
  const BackendChoice backend = resolveBakeBackend(*requested, device);
  if (backend.backend == BakeBackend::kVulkan && options.target_error > 0) {
    return std::fprintf(stderr,
                        "rdm bake: --target-error is not supported on the Vulkan backend; use "
                        "--backend cpu\n"),
           2;
  }
  if (!parser.flag("--quiet"))
    std::printf("backend:   %s (%s)\n", bakeBackendName(backend.backend), backend.reason.c_str());

  VoxelWorld world = buildWorld(*scene);
  ProgressReporter progress("RDMs");
  if (!parser.flag("--quiet")) {
    options.on_progress = [&](const BakeProgress& p) {
      progress.update(p.rdms_done, p.rdms_total, p.rays, p.seconds);
    };
  }
  BakeResult result;
  std::string device_name = "cpu";
  if (backend.backend == BakeBackend::kVulkan) {
    std::vector<RdmId> all = listRdms(world, scene->bake), mine;
    for (size_t i = 0; i < all.size(); ++i) {
      if (int(i % size_t(options.shard_count)) == options.shard_index) mine.push_back(all[i]);
    }
    VulkanBakeOptions vk;
    VulkanBakeInfo info;
    vk.device = device;
    vk.on_progress = options.on_progress;
    vk.info = &info;
    auto baked = bakeRdmsVulkan(world, scene->bake, mine, vk);
    progress.finish();
    if (!baked) return std::fprintf(stderr, "rdm bake: %s\n", baked.error().c_str()), 1;
    result = std::move(*baked);
    device_name = info.device.name;
  } else {
    result = bakeScene(world, scene->bake, options);
    progress.finish();
  }
  const int threads = backend.backend == BakeBackend::kVulkan ? 0
                      : options.threads > 0                   ? options.threads
                                            : int(std::thread::hardware_concurrency());
  if (options.shard_count > 1 || parser.value("--shard")) {
    ShardManifest m{options.shard_index, options.shard_count, sceneDigest(*scene),
                    int(listRdms(world, scene->bake).size())};
    if (Status s = writeShard(*out, m, result.rdms); !s)
      return std::fprintf(stderr, "rdm bake: %s\n", s.message().c_str()), 1;
    printSummary(result.report, nullptr, *scene);
    std::printf("wrote shard %d/%d (%zu RDMs) to %s\n", m.index, m.count, result.rdms.size(),
                out->c_str());
    return 0;
  }
  std::vector<RdmId> ids;
  for (const RdmData& d : result.rdms) ids.push_back(d.id);
  AtlasLayout layout = packCanonical(ids);
  if (Status s = writeAtlasOutputs(*out, layout, result.rdms); !s) {
    return std::fprintf(stderr, "rdm bake: %s\n", s.message().c_str()), 1;
  }
  writeFileAtomic(*out + "/bake_report.json",
                  reportJson(result.report, &layout, *scene, threads,
                             bakeBackendName(backend.backend), device_name)
                          .dump(1) +
                      "\n");
  printSummary(result.report, &layout, *scene);
  std::printf("wrote %s/atlas.exr, index.json, index.txt, bake_report.json\n", out->c_str());
  return 0;
}

}  // namespace rdm::cli
