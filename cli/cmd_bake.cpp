#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <optional>

#include "bake_summary.h"
#include "cli_app.h"
#include "commands.h"
#include "noise_map.h"
#include "output_check.h"
#include "progress.h"
#include "rdm/atlas/atlas.h"
#include "rdm/atlas/bake_estimate.h"
#include "rdm/bake/bake.h"
#include "rdm/bake/bake_prediction.h"
#include "rdm/bake/face_light.h"
#include "rdm/bake/shard.h"
#include "rdm/base/file_util.h"
#include "rdm/base/machine.h"
#include "rdm/base/parallel.h"
#include "rdm/vulkan/vulkan_bake.h"
#include "scene_options.h"

namespace rdm::cli {
namespace {

// Set by the first SIGINT; the bake stops between work units. The handler resets itself,
// so a second Ctrl-C ends the process at once.
std::atomic<bool> g_cancel{false};
static_assert(std::atomic<bool>::is_always_lock_free);

extern "C" void onInterrupt(int) {
  g_cancel.store(true);
}

void installInterruptHandler(bool reset_after_first) {
  struct sigaction action {};
  action.sa_handler = onInterrupt;
  action.sa_flags = reset_after_first ? SA_RESETHAND : 0;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
}

struct BakeArgs {
  SceneArgs scene;
  std::string out, shard, backend = "auto", device, quality, radiance = "float32";
  int threads = 0, max_spp_factor = 16, face_light_spp = -1;  // -1: the scene's
  uint64_t max_memory = 0;                                    // 0: MemAvailable
  double target_error = 0.0;
  bool quiet = false, predict = false;
};

void addOptions(CLI::App& app, BakeArgs& a) {
  addSceneOptions(app, a.scene, "samples per texel (with --target-error: the first pass)");
  app.add_option("-o,--output", a.out, "output directory (created; checked before the bake)")
      ->required();
  app.add_option("--threads", a.threads, "CPU threads (0: all cores)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--target-error", a.target_error,
                 "sample each texel until its relative standard error is below E (0: off)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--max-spp-factor", a.max_spp_factor,
                 "with --target-error, stop a texel at spp * this many samples")
      ->check(CLI::PositiveNumber);
  app.add_option("--shard", a.shard,
                 "bake only shard I of N (I/N, 0 <= I < N); merge with rdm merge")
      ->default_str("none");
  app.add_option("--backend", a.backend,
                 "cpu, vulkan, or auto (a Vulkan GPU if one exists, else the CPU; "
                 "docs/vulkan.md)");
  app.add_option("--device", a.device, "Vulkan device by index or name")->default_str("first GPU");
  app.add_option("--quality", a.quality,
                 "preset: draft (4 spp, 2 bounces), preview (16, 4) or final (128, 6), "
                 "prefiltered; --spp, --max-bounces and --estimator given as well win. "
                 "Predicts time and noise first")
      ->check(CLI::IsMember({"draft", "preview", "final"}));
  app.add_flag("--predict", a.predict,
               "predict the bake's time and noise from a small pilot bake before starting "
               "(CPU backend; implied by --quality)");
  app.add_option("--radiance", a.radiance,
                 "atlas radiance: float32, or half (R, G, B at 16 bits with a power-of-two "
                 "scale per face tile, so values above 65504 survive; Z stays float32)")
      ->check(CLI::IsMember({"float32", "half"}))
      ->default_str("float32");
  app.add_option("--face-light", a.face_light_spp,
                 "also bake the light of every exposed voxel face with this many samples per "
                 "face into face_light.bin (docs/spec.md section 3.2; CPU; 0: off)")
      ->check(CLI::Range(0, 1 << 16))
      ->default_str("scene's bake.face_light_spp");
  app.add_option("--max-memory", a.max_memory,
                 "refuse a bake whose estimated peak memory exceeds this many bytes")
      ->default_str("the memory available now (MemAvailable)");
  app.add_flag("-q,--quiet", a.quiet, "no progress and no backend line");
}

// The spill file holds every RDM of this shard while the atlas waits.
uint64_t spillBytes(const std::vector<RdmId>& rdms) {
  uint64_t bytes = 0;
  for (const RdmId& id : rdms) bytes += RdmSpill::fileBytes(id);
  return bytes;
}

// The pilot's line ends (its progress rewrote it), then what it predicts, with the cores it
// assumed and what it cost beside the bake it predicts.
void printPrediction(const BakePrediction& p, const Scene& scene, const BakeArgs& a) {
  char load[32] = "load unknown";
  if (p.load_average >= 0.0) std::snprintf(load, sizeof load, "load %.2f", p.load_average);
  std::printf(
      "%spredicted:   %s (%.2f CPU-s) for the RDMs%s, mean relative standard error %.2f %% "
      "(%s%s, %d spp), assuming %.1f free cores (%s)%s\n"
      "pilot:       %d + %d of %d slots took %.2f s, %.2f CPU-s (%.0f %% of the bake)\n",
      isatty(fileno(stdout)) ? "\n" : "", predictedTimeText(p.seconds).c_str(), p.cpu_seconds,
      a.face_light_spp > 0 ? " (the face light after them is not predicted)" : "",
      100.0 * p.relative_error, a.quality.empty() ? "" : "quality ",
      a.quality.empty() ? "custom" : a.quality.c_str(), scene.bake.spp, p.free_cores, load,
      p.cheap ? " (a cheap bake, under 1 CPU-s: rough numbers)" : "", p.sampled_slots,
      p.pilot_slots, p.slots, p.pilot_seconds, p.pilot_cpu_seconds,
      p.cpu_seconds > 0.0 ? 100.0 * p.pilot_cpu_seconds / p.cpu_seconds : 0.0);
  std::fflush(stdout);
}

// Prints what the bake will take and refuses (exit 1) when this machine cannot hold it:
// peak memory over --max-memory or what is available, or the spill and outputs over the
// free disk.
std::optional<int> checkEstimate(const VoxelWorld& world, const Scene& scene,
                                 const BakeOptions& options, const BakeArgs& a) {
  const RadianceFormat radiance = *parseRadianceFormat(a.radiance);  // CLI11 checked the name
  const BakeEstimate e = estimateBake(world, scene.bake, radiance, workerCount(options.threads));
  const uint64_t spill =
      spillBytes(shardRdms(world, scene.bake, options.shard_index, options.shard_count));
  const uint64_t disk = spill + e.atlas_bytes + e.texels * 4;  // + the noise map's float
  if (!a.quiet) {
    std::printf(
        "estimate:    %zu RDMs of %zu blocks, %s texels, atlas %d page(s) of %s (%s), peak "
        "memory %s, disk %s during the bake\n",
        e.rdms, e.blocks, formatCount(double(e.texels)).c_str(), e.pages,
        formatBytes(e.atlas_bytes).c_str(), a.radiance.c_str(),
        formatBytes(e.peak_memory_bytes).c_str(), formatBytes(disk).c_str());
  }
  const uint64_t memory_limit = a.max_memory ? a.max_memory : availableMemoryBytes();
  const std::string advice =
      "; lower --max-hemisphere (texels grow with its square), use --radiance half, or bake "
      "in shards (--shard I/N, then rdm merge)";
  if (e.peak_memory_bytes > memory_limit) {
    return fail("bake", "the bake needs about " + formatBytes(e.peak_memory_bytes) +
                            " of memory, more than " +
                            (a.max_memory ? "--max-memory (" : "this machine has available (") +
                            formatBytes(memory_limit) + ")" + advice);
  }
  const uint64_t free_disk = freeDiskBytes(a.out);
  if (free_disk > 0 && disk > free_disk) {
    return fail("bake", "the bake needs about " + formatBytes(disk) + " of disk in " + a.out +
                            " (spill file and outputs), more than is free (" +
                            formatBytes(free_disk) + ")" + advice);
  }
  return std::nullopt;
}

// The face light of the whole scene on the CPU, timed beside the RDM bake.
struct FaceLightBake {
  FaceLight light;
  double seconds = 0.0;
};
FaceLightBake bakeFaceLightTimed(const VoxelWorld& world, const Scene& scene, const BakeArgs& a,
                                 const BakeOptions& bake) {
  FaceLightBake out;
  const auto start = std::chrono::steady_clock::now();
  FaceLightOptions options;
  options.threads = a.threads, options.spp = a.face_light_spp;
  options.shard_index = bake.shard_index, options.shard_count = bake.shard_count;
  out.light = bakeFaceLight(world, scene, options);
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

Status writeFaceLightOutput(const BakeArgs& a, const FaceLightBake& f, double rdm_seconds) {
  if (Status s = writeFaceLight(a.out + "/" + kFaceLightFile, f.light); !s) return s;
  std::printf("face light:  %zu faces of %zu slots, %u spp, %.2f s (%.0f %% of the RDM bake)\n",
              f.light.faceCount(), f.light.slots.size(), f.light.spp, f.seconds,
              rdm_seconds > 0.0 ? 100.0 * f.seconds / rdm_seconds : 0.0);
  return {};
}

// --quality's preset under the explicit overrides, which win.
void applyQuality(const BakeArgs& a, Scene& scene) {
  if (a.quality.empty()) return;
  auto preset = qualityPreset(a.quality);
  if (!preset) return;  // CLI11 checked the name
  scene.bake = withPreset(scene.bake, *preset);
  const SceneArgs& s = a.scene;
  if (s.spp_option && *s.spp_option) scene.bake.spp = s.spp;
  if (*s.bounces_option) scene.bake.max_bounces = s.max_bounces;
  // sceneFromArgs parsed --estimator already.
  if (*s.estimator_option) scene.bake.estimator = *parseEstimator(s.estimator);
}

bool parseShard(const std::string& text, int& index, int& count) {
  char rest = 0;
  return std::sscanf(text.c_str(), "%d/%d%c", &index, &count, &rest) == 2 && count >= 1 &&
         index >= 0 && index < count;
}

// Bakes this shard's RDMs on `backend`, with progress unless --quiet; stops between units
// after a Ctrl-C (report.cancelled).
Expected<BakeResult> runBake(const VoxelWorld& world, const Scene& scene,
                             const BakeOptions& options, BakeBackend backend, const BakeArgs& a,
                             BakeContext& context) {
  const std::vector<RdmId> mine =
      shardRdms(world, scene.bake, options.shard_index, options.shard_count);
  ProgressReporter progress("RDMs");
  bool announced = false;
  auto announceCancel = [&] {
    if (announced || !g_cancel.load()) return;
    announced = true;
    std::fprintf(stderr,
                 "\nrdm bake: interrupted: finishing the work units in progress, then stopping "
                 "without writing (Ctrl-C again to quit at once)\n");
  };
  if (backend == BakeBackend::kVulkan) {
    VulkanBakeOptions vk;
    VulkanBakeInfo info;
    vk.device = a.device;
    vk.cancel = &g_cancel;
    vk.info = &info;
    vk.on_progress = [&](const BakeProgress& p) {
      announceCancel();
      if (!a.quiet)
        progress.update(p.rdms_done, p.rdms_total, p.rdms_done, p.rdms_total, p.rays, p.seconds);
    };
    auto baked = bakeRdmsVulkan(world, scene.bake, mine, vk);
    announceCancel();  // a Ctrl-C after the last progress report
    progress.finish();
    if (baked) context.device = info.device.name;
    return baked;
  }
  BakeOptions cpu = options;
  cpu.on_progress = [&](const BakeProgress& p) {
    announceCancel();
    if (!a.quiet) {
      progress.update(double(p.texels_done), double(p.texels_total), p.rdms_done, p.rdms_total,
                      p.rays, p.seconds);
    }
  };
  BakeResult result = bakeRdms(world, scene.bake, mine, cpu);
  announceCancel();  // a Ctrl-C after the last progress report
  progress.finish();
  context.threads = workerCount(options.threads);
  return result;
}

nlohmann::json reportWithFaceLight(const BakeResult& result, const AtlasLayout& layout,
                                   const BakeContext& context, const FaceLightBake* face_light) {
  nlohmann::json report = bakeReportJson(result, &layout, context);
  if (face_light) {
    report["face_light"] = {{"spp", face_light->light.spp},
                            {"faces", face_light->light.faceCount()},
                            {"seconds", face_light->seconds}};
  }
  return report;
}

// A shard directory, or the atlas, noise map and bake_report.json; then the summary.
int writeResults(const BakeResult& result, const RdmSource& rdms, const VoxelWorld& world,
                 const Scene& scene, const BakeOptions& options, const BakeArgs& a,
                 const BakeContext& context, const FaceLightBake* face_light) {
  if (options.shard_count > 1 || !a.shard.empty()) {
    ShardManifest m{options.shard_index, options.shard_count, sceneDigest(scene),
                    int(listRdms(world, scene.bake).size())};
    if (Status s = writeShard(a.out, m, rdms); !s) return fail("bake", s.message());
    printBakeSummary(result, nullptr, context);
    if (face_light) {
      if (Status s = writeFaceLightOutput(a, *face_light, result.report.seconds); !s)
        return fail("bake", s.message());
    }
    std::printf("wrote shard %d/%d (%zu RDMs) to %s\n", m.index, m.count, result.rdms.size(),
                a.out.c_str());
    return 0;
  }
  std::vector<RdmId> ids;
  for (const RdmData& d : result.rdms) ids.push_back(d.id);
  AtlasLayout layout = packCanonical(ids, storedFacesOf(result.rdms));
  layout.radiance = *parseRadianceFormat(a.radiance);  // CLI11 checked the name
  if (Status s = writeAtlasOutputs(a.out, layout, rdms); !s) return fail("bake", s.message());
  if (Status s = writeNoiseMaps(a.out, layout, rdms); !s) return fail("bake", s.message());
  if (Status s =
          writeFileAtomic(a.out + "/bake_report.json",
                          reportWithFaceLight(result, layout, context, face_light).dump(1) + "\n");
      !s)
    return fail("bake", s.message());
  printBakeSummary(result, &layout, context);
  if (face_light) {
    if (Status s = writeFaceLightOutput(a, *face_light, result.report.seconds); !s)
      return fail("bake", s.message());
  }
  std::printf("wrote %s/atlas.exr, index.json, index.txt, noise.exr, bake_report.json\n",
              a.out.c_str());
  return 0;
}

}  // namespace

int cmdBake(const Args& args) {
  BakeArgs a;
  VerbApp app("bake",
              "Bake the RDM atlas of a scene: DIR/atlas.exr, index.json, index.txt, "
              "noise.exr (per-texel relative standard error) and bake_report.json.\n"
              "Ctrl-C stops between work units and writes nothing.");
  addOptions(app, a);
  if (auto code = parseArgs(app, args)) return *code;
  BakeOptions options;
  options.threads = a.threads;
  options.target_error = a.target_error;
  options.max_spp_factor = a.max_spp_factor;
  options.cancel = &g_cancel;
  if (!a.shard.empty() && !parseShard(a.shard, options.shard_index, options.shard_count))
    return fail("bake", "--shard expects I/N with 0 <= I < N, got '" + a.shard + "'", 2);
  auto scene = sceneFromArgs(a.scene);
  if (!scene) return fail("bake", scene.error());
  applyQuality(a, *scene);
  if (a.face_light_spp < 0) a.face_light_spp = scene->face_light_spp;
  auto requested = parseBakeBackend(a.backend);
  if (!requested) return fail("bake", requested.error(), 2);
  if (!a.device.empty() && *requested == BakeBackend::kCpu)
    return fail("bake", "--device selects a Vulkan device; it does not apply to --backend cpu", 2);
  BackendChoice backend = resolveBakeBackend(*requested, a.device);
  if (backend.backend == BakeBackend::kVulkan && scene->bake.estimator != Estimator::kNaive) {
    if (*requested == BakeBackend::kVulkan) {
      return fail("bake",
                  "the Vulkan backend has only the naive estimator; add --estimator naive or "
                  "use --backend cpu",
                  2);
    }
    backend = {BakeBackend::kCpu, "auto: the prefiltered estimator runs on the CPU only"};
  }
  if (backend.backend == BakeBackend::kVulkan && options.target_error > 0) {
    return fail("bake", "--target-error is not supported on the Vulkan backend; use --backend cpu",
                2);
  }
  bool created_output = false;
  if (Status s = prepareOutputDirectory(a.out, created_output); !s)
    return fail("bake", s.message());
  if (!a.quiet)
    std::printf("backend:     %s (%s)\n", bakeBackendName(backend.backend), backend.reason.c_str());
  std::fflush(stdout);

  VoxelWorld world = buildWorld(*scene);
  if (auto refused = checkEstimate(world, *scene, options, a)) {
    if (created_output) removeIfEmpty(a.out);
    return *refused;
  }
  BakeContext context{
      &*scene, options.target_error, options.max_spp_factor, 0, bakeBackendName(backend.backend),
      "cpu"};
  BakePrediction prediction;
  if ((a.predict || !a.quality.empty()) && backend.backend == BakeBackend::kCpu) {
    const int threads = workerCount(options.threads);
    prediction = predictBake(
        world, scene->bake, shardRdms(world, scene->bake, options.shard_index, options.shard_count),
        threads, [&, terminal = isatty(fileno(stdout)) != 0](double fraction) {
          if (a.quiet || !terminal) return;  // a log gets the pilot's summary line only
          std::printf("\rpilot:       %3.0f %%", 100.0 * fraction);
          std::fflush(stdout);
        });
    context.prediction = &prediction;
    context.quality = a.quality;
    if (!a.quiet) printPrediction(prediction, *scene, a);
  }
  // CPU bakes hand each RDM to a spill file as it finishes, so memory holds the RDMs in
  // flight; the atlas, noise map and shard are then written from it one RDM at a time.
  std::unique_ptr<RdmSpill> spill;
  if (backend.backend == BakeBackend::kCpu) {
    auto created = RdmSpill::create(a.out);
    if (!created) return fail("bake", created.error());
    spill = std::move(*created);
    options.on_rdm_done = [&spill](const RdmData& rdm) { spill->append(rdm); };
  }
  installInterruptHandler(true);
  auto result = runBake(world, *scene, options, backend.backend, a, context);
  // A Ctrl-C from here on is recorded and ignored: the results are complete, and the writes
  // are short and atomic.
  installInterruptHandler(false);
  if (!result || result->report.cancelled) {
    if (created_output) removeIfEmpty(a.out);
    if (!result) return fail("bake", result.error());
    char when[32];
    std::snprintf(when, sizeof when, "%.1f s", result->report.seconds);
    return fail("bake",
                std::string("cancelled after ") + when + "; nothing was written to " + a.out, 130);
  }
  if (spill) {
    if (Status s = spill->status(); !s) return fail("bake", s.message() + "; nothing was written");
  }
  std::optional<FaceLightBake> face_light;
  if (a.face_light_spp > 0) face_light = bakeFaceLightTimed(world, *scene, a, options);
  const MemoryRdmSource in_memory(result->rdms);
  const RdmSource& rdms = spill ? static_cast<const RdmSource&>(*spill) : in_memory;
  return writeResults(*result, rdms, world, *scene, options, a, context,
                      face_light ? &*face_light : nullptr);
}

}  // namespace rdm::cli
