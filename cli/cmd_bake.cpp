#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <mutex>
#include <optional>

#include "bake_denoise.h"
#include "bake_face_light.h"
#include "bake_summary.h"
#include "cli_app.h"
#include "commands.h"
#include "interrupt.h"
#include "number_checks.h"
#include "output_check.h"
#include "progress.h"
#include "rdm/atlas/atlas.h"
#include "rdm/atlas/bake_estimate.h"
#include "rdm/atlas/noise_map.h"
#include "rdm/atlas/slot_sets_file.h"
#include "rdm/bake/bake.h"
#include "rdm/bake/bake_prediction.h"
#include "rdm/bake/face_light.h"
#include "rdm/bake/shard.h"
#include "rdm/base/file_util.h"
#include "rdm/base/machine.h"
#include "rdm/base/parallel.h"
#include "rdm/image/exr_io.h"
#include "rdm/vulkan/vulkan_bake.h"
#include "rdm/vulkan/vulkan_bc6h.h"
#include "scene_options.h"
#include "written_files.h"

namespace rdm::cli {
namespace {

struct BakeArgs {
  SceneArgs scene;
  std::string out, shard, backend = "auto", device, quality, radiance = "float32";
  std::string bc6h_encoder = "auto", denoise_scope = "blocks", denoise_device = "auto";
  int threads = 0, max_spp_factor = 16, face_light_spp = -1;  // -1: the scene's
  uint64_t max_memory = 0;                                    // 0: MemAvailable
  double target_error = 0.0;
  bool quiet = false, predict = false, no_slot_sets = false, denoise = false;
};

void addOptions(CLI::App& app, BakeArgs& a) {
  addSceneOptions(app, a.scene, "samples per texel (with --target-error: the first pass)");
  app.add_option("-o,--output", a.out, "output directory (created; checked before the bake)")
      ->required();
  app.add_option("--threads", a.threads, "CPU threads (0: all cores)")
      ->check(countOrZero("all cores"));
  app.add_option("--target-error", a.target_error,
                 "sample each texel until its relative standard error is below E (0: off)")
      ->check(numberOrZero("off"));
  app.add_option("--max-spp-factor", a.max_spp_factor,
                 "with --target-error, stop a texel at spp * this many samples")
      ->check(positiveCount());
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
                 "atlas radiance: float32; half (R, G, B at 16 bits with a power-of-two "
                 "scale per face tile, so values above 65504 survive; Z stays float32); or "
                 "bc6h (R, G, B as BC6H in atlas.ktx2 with the same scale, tiles aligned to "
                 "4x4 blocks; Z as half in depth.exr; docs/bc6h.md)")
      ->check(CLI::IsMember({"float32", "half", "bc6h"}))
      ->default_str("float32");
  app.add_option("--bc6h-encoder", a.bc6h_encoder,
                 "with --radiance bc6h: encode on the cpu, on vulkan (the --device), or auto "
                 "(Vulkan when the bake runs on a Vulkan GPU); the blocks are the same "
                 "(docs/bc6h.md)")
      ->check(CLI::IsMember({"auto", "cpu", "vulkan"}))
      ->default_str("auto");
  app.add_option("--face-light", a.face_light_spp,
                 "also bake the light of every exposed voxel face with this many samples per "
                 "face into face_light.bin (docs/spec.md section 3.2; on the bake's "
                 "backend; 0: off)")
      ->check(wholeNumberIn(0, 1 << 16))
      ->default_str("scene's bake.face_light_spp");
  app.add_flag("--denoise", a.denoise,
               "filter the RDMs across block borders before writing, guided by depth and each "
               "texel's standard error; noise.exr then reports the filtered error "
               "(docs/denoise.md)");
  app.add_option("--denoise-scope", a.denoise_scope,
                 "with --denoise: blocks (each face with the same face of the blocks beside it) "
                 "or tile (each face's own map, the per-tile filter, for comparison)")
      ->check(CLI::IsMember({"blocks", "tile"}))
      ->default_str("blocks");
  app.add_option("--denoise-device", a.denoise_device,
                 "with --denoise: filter on the cpu, on vulkan (the --device), or auto (Vulkan "
                 "when the bake runs on a Vulkan GPU); the same filter (docs/denoise.md)")
      ->check(CLI::IsMember({"auto", "cpu", "vulkan"}))
      ->default_str("auto");
  app.add_option("--max-memory", a.max_memory,
                 "refuse a bake whose estimated peak memory exceeds this many bytes")
      ->check(countOrZero("the memory available now"))
      ->default_str("the memory available now (MemAvailable)");
  app.add_flag("--no-slot-sets", a.no_slot_sets,
               "do not record the slot sets rdms.bin holds (the viewer's first in-process "
               "rebake from this atlas then bakes every RDM); docs/performance.md gives the cost");
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
  const BakeEstimate e = estimateBake(world, scene.bake, radiance, workerCount(options.threads),
                                      {options.record_slot_sets, a.denoise});
  const uint64_t spill =
      spillBytes(shardRdms(world, scene.bake, options.shard_index, options.shard_count));
  // The spill (twice with the denoiser's), the atlas and the noise map's float a texel.
  const uint64_t disk = (a.denoise ? 2 : 1) * spill + e.atlas_bytes + e.texels * 4;
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
                             const BakeOptions& options, VulkanBaker* vulkan, const BakeArgs& a,
                             BakeContext& context) {
  const std::vector<RdmId> mine =
      shardRdms(world, scene.bake, options.shard_index, options.shard_count);
  ProgressReporter progress("RDMs");
  auto announceCancel = [] { announceInterrupt("bake"); };
  if (vulkan) {
    VulkanBakeOptions vk;
    VulkanBakeInfo info;
    vk.record_slot_sets = options.record_slot_sets;  // rdms.bin
    vk.target_error = options.target_error;
    vk.max_spp_factor = options.max_spp_factor;
    vk.on_rdm_done = options.on_rdm_done;
    vk.cancel = interruptFlag();
    vk.info = &info;
    vk.on_progress = [&](const BakeProgress& p) {
      announceCancel();
      if (!a.quiet)
        progress.update(p.rdms_done, p.rdms_total, p.rdms_done, p.rdms_total, p.rays, p.seconds);
    };
    auto baked = vulkan->bake(world, scene.bake, mine, vk);
    announceCancel();  // a Ctrl-C after the last progress report
    progress.finish();
    context.device = vulkan->device().name;
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

// rdms.bin's records, taken as each RDM finishes (the bake then frees its sets; as records
// they are runs of slot indices, a fraction of the u32 lists).
class SlotSetRecords {
 public:
  void add(const RdmData& rdm) {
    RdmRecord record = recordOf(rdm, "");
    std::lock_guard<std::mutex> lock(mutex_);
    records_.push_back(std::move(record));
  }
  // rdms.bin: the slot sets an in-process rebake starting from this atlas needs.
  Status write(const std::string& dir) { return writeSlotSetsFile(dir, std::move(records_)); }

 private:
  std::mutex mutex_;
  std::vector<RdmRecord> records_;
};

// A shard directory: shard.json, one file per RDM, and face_light.bin when baked.
int writeShardResults(const BakeResult& result, const RdmSource& rdms, SlotSetRecords& sets,
                      const VoxelWorld& world, const Scene& scene, const BakeOptions& options,
                      const BakeArgs& a, const BakeContext& context,
                      const FaceLightBake* face_light) {
  ShardManifest m{options.shard_index, options.shard_count, sceneDigest(scene),
                  int(listRdms(world, scene.bake).size()), lightingFingerprint(scene, scene.bake)};
  if (Status s = writeShard(a.out, m, rdms); !s) return fail("bake", s.message());
  if (options.record_slot_sets) {
    if (Status s = sets.write(a.out); !s) return fail("bake", s.message());
  }
  printBakeSummary(result, nullptr, context);
  if (face_light) {
    if (Status s = writeFaceLightOutput(a.out, *face_light, result.report.seconds); !s)
      return fail("bake", s.message());
  }
  std::printf("wrote shard %d/%d to %s: shard.json, %zu RDM files%s%s\n", m.index, m.count,
              a.out.c_str(), result.rdms.size(), options.record_slot_sets ? ", rdms.bin" : "",
              face_light ? ", face_light.bin" : "");
  return 0;
}

// A shard directory, or the atlas, noise map, face light and bake_report.json; then the
// summary and the names of every file written.
int writeResults(const BakeResult& result, const RdmSource& rdms, SlotSetRecords& sets,
                 const VoxelWorld& world, const Scene& scene, const BakeOptions& options,
                 const BakeArgs& a, const BakeContext& context, const FaceLightBake* face_light,
                 const Bc6hEncodeFn& bc6h) {
  if (options.shard_count > 1 || !a.shard.empty())
    return writeShardResults(result, rdms, sets, world, scene, options, a, context, face_light);
  std::vector<RdmId> ids;
  for (const RdmData& d : result.rdms) ids.push_back(d.id);
  const RadianceFormat radiance = *parseRadianceFormat(a.radiance);  // CLI11 checked the name
  AtlasLayout layout = packCanonical(ids, storedFacesOf(result.rdms), radiance);
  layout.lighting = lightingFingerprint(scene, scene.bake);
  if (Status s = writeAtlasOutputs(a.out, layout, rdms, bc6h); !s) return fail("bake", s.message());
  if (Status s = writeNoiseMaps(a.out, layout, rdms); !s) return fail("bake", s.message());
  if (options.record_slot_sets) {
    if (Status s = sets.write(a.out); !s) return fail("bake", s.message());
  }
  if (Status s =
          writeFileAtomic(a.out + "/bake_report.json",
                          reportWithFaceLight(result, layout, context, face_light).dump(1) + "\n");
      !s)
    return fail("bake", s.message());
  printBakeSummary(result, &layout, context);
  if (face_light) {
    if (Status s = writeFaceLightOutput(a.out, *face_light, result.report.seconds); !s)
      return fail("bake", s.message());
  }
  const WrittenFiles written{layout.pages.size(), true, face_light != nullptr,
                             options.record_slot_sets, radiance == RadianceFormat::kBc6h};
  std::printf("wrote %s\n", writtenFilesLine(a.out, written).c_str());
  return 0;
}

// A validated bake: the arguments, the scene with every override applied and the backend.
struct BakePlan {
  BakeArgs a;
  BakeOptions options;
  Scene scene;
  BackendChoice backend;
  std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
};

// The backend for `plan`'s request; nullopt, or the exit code after a usage error.
std::optional<int> chooseBackend(BakePlan& plan) {
  const BakeArgs& a = plan.a;
  auto requested = parseBakeBackend(a.backend);
  if (!requested) return fail("bake", requested.error(), 2);
  if (!a.device.empty() && *requested == BakeBackend::kCpu)
    return fail("bake", "--device selects a Vulkan device; it does not apply to --backend cpu", 2);
  plan.backend = resolveBakeBackend(*requested, a.device, plan.scene);
  if (plan.backend.backend == BakeBackend::kVulkan && a.predict) {
    return fail("bake",
                "--predict times a pilot of a CPU bake; it is not supported on the Vulkan "
                "backend; use --backend cpu",
                2);
  }
  return std::nullopt;
}

// Parses and checks everything before any work; nullopt, or the exit code to return.
std::optional<int> planBake(const Args& args, BakePlan& plan) {
  BakeArgs& a = plan.a;
  VerbApp app("bake",
              "Bake the RDM atlas of a scene: DIR/atlas.exr, index.json, index.txt, "
              "noise.exr (per-texel relative standard error), face_light.bin (with a face "
              "light) and bake_report.json.\n"
              "Ctrl-C stops between work units and writes nothing.");
  addOptions(app, a);
  if (auto code = parseArgs(app, args)) return code;
  BakeOptions& options = plan.options;
  options.threads = a.threads;
  options.target_error = a.target_error;
  options.max_spp_factor = a.max_spp_factor;
  options.cancel = interruptFlag();
  options.record_slot_sets = !a.no_slot_sets;  // rdms.bin
  if (!a.shard.empty() && !parseShard(a.shard, options.shard_index, options.shard_count))
    return fail("bake", "--shard expects I/N with 0 <= I < N, got '" + a.shard + "'", 2);
  if (a.denoise && !a.shard.empty())
    return fail("bake",
                "--denoise filters across blocks, which a shard does not all hold; denoise the "
                "whole bake",
                2);
  if (Status s = checkSceneArgs(a.scene); !s) return fail("bake", s.message(), 2);
  auto scene = sceneFromArgs(a.scene);
  if (!scene) return fail("bake", scene.error());
  plan.scene = std::move(*scene);
  applyQuality(a, plan.scene);
  if (a.face_light_spp < 0) a.face_light_spp = plan.scene.face_light_spp;
  if (a.denoise && plan.scene.bake.estimator == Estimator::kNaive && plan.scene.bake.spp < 2) {
    return fail("bake",
                "--denoise is guided by each texel's standard error, which the naive estimator "
                "cannot give from 1 sample: use --spp 2 or more, or the prefiltered estimator",
                2);
  }
  return chooseBackend(plan);
}

// The pilot bake of --quality and --predict, printed before the bake; a Ctrl-C during it
// takes effect when it ends.
void predict(const VoxelWorld& world, const BakePlan& plan, BakePrediction& prediction,
             BakeContext& context) {
  const BakeArgs& a = plan.a;
  const BakeOptions& options = plan.options;
  prediction = predictBake(
      world, plan.scene.bake,
      shardRdms(world, plan.scene.bake, options.shard_index, options.shard_count),
      workerCount(options.threads), [&, terminal = isatty(fileno(stdout)) != 0](double fraction) {
        announceInterrupt("bake");
        if (a.quiet || !terminal) return;  // a log gets the pilot's summary line only
        std::printf("\rpilot:       %3.0f %%", 100.0 * fraction);
        std::fflush(stdout);
      });
  context.prediction = &prediction;
  if (!a.quiet) printPrediction(prediction, plan.scene, a);
}

// The implicit pilot of --quality is skipped when the bake is estimated too cheap to be worth
// it (pilotWorthRunning); one line says so. bake_report.json then has no `predicted`.
bool skipPilot(const VoxelWorld& world, const BakePlan& plan) {
  const BakeArgs& a = plan.a;
  const int threads = workerCount(plan.options.threads);
  const RadianceFormat radiance = *parseRadianceFormat(a.radiance);  // CLI11 checked the name
  // A shard bakes about 1/N of the scene's RDMs.
  const double cpu_seconds = estimateBake(world, plan.scene.bake, radiance, threads).cpu_seconds /
                             double(std::max(1, plan.options.shard_count));
  if (pilotWorthRunning(cpu_seconds)) return false;
  if (!a.quiet) {
    std::printf(
        "prediction:  skipped, the bake is too cheap for its pilot (estimated %.1f CPU-s, "
        "under %.1f: the pilot would cost over %.0f %% of it); --predict runs it\n",
        cpu_seconds, kSkipPilotBelowEstimatedCpuSeconds, 100.0 * kMaxPilotShare);
    std::fflush(stdout);
  }
  return true;
}

// Exit 130 after a Ctrl-C, having written nothing (an output directory the bake created is
// removed again).
int cancelled(const BakePlan& plan, bool created_output) {
  announceInterrupt("bake");
  if (created_output) removeIfEmpty(plan.a.out);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - plan.start).count();
  char when[32];
  std::snprintf(when, sizeof when, "%.1f s", seconds);
  return fail("bake",
              std::string("cancelled after ") + when + "; nothing was written to " + plan.a.out,
              130);
}

// The BC6H encoder of --radiance bc6h (kept alive with the function that calls it).
struct Bc6hEncoderChoice {
  std::shared_ptr<VulkanBc6hEncoder> device;
  Bc6hEncodeFn encode;  // empty: the CPU's
};

// --bc6h-encoder: `auto` encodes on the bake's Vulkan device when it is a GPU; on lavapipe the
// CPU encoder is about 11x faster on the same cores (docs/bc6h.md). Either gives the same blocks.
Expected<Bc6hEncoderChoice> bc6hEncoder(const BakeArgs& a, const VulkanBaker* baker) {
  Bc6hEncoderChoice choice;
  const bool on_gpu = baker && baker->device().type != "cpu";
  if (a.radiance != "bc6h" || a.bc6h_encoder == "cpu" || (a.bc6h_encoder == "auto" && !on_gpu))
    return choice;
  auto created = VulkanBc6hEncoder::create(a.device);
  if (!created) return Status::error("--bc6h-encoder vulkan: " + created.error());
  choice.device = std::move(*created);
  choice.encode = [device = choice.device](const Image& image) { return device->encode(image); };
  return choice;
}

// The Vulkan denoiser of --denoise --denoise-device (auto: when the bake runs on a Vulkan GPU),
// made before the bake so that a missing device fails it at once; null: the CPU.
Expected<std::unique_ptr<VulkanDenoiser>> denoiseDevice(const BakeArgs& a,
                                                        const VulkanBaker* baker) {
  const bool on_gpu = baker && baker->device().type != "cpu";
  if (!a.denoise || a.denoise_device == "cpu" || (a.denoise_device == "auto" && !on_gpu))
    return std::unique_ptr<VulkanDenoiser>();
  auto created = VulkanDenoiser::create(a.device);
  if (!created) return Status::error("--denoise-device vulkan: " + created.error());
  return std::move(*created);
}

// The pilot, the RDMs and the face light, checking for a Ctrl-C after each; then the writes.
int bakeAndWrite(BakePlan& plan, const VoxelWorld& world, BakeContext& context,
                 bool created_output) {
  const BakeArgs& a = plan.a;
  BakeOptions& options = plan.options;
  const BakeBackend backend = plan.backend.backend;
  BakePrediction prediction;
  context.quality = a.quality;
  if ((a.predict || !a.quality.empty()) && backend == BakeBackend::kCpu) {
    if (a.predict || !skipPilot(world, plan)) predict(world, plan, prediction, context);
  }
  if (interrupted()) return cancelled(plan, created_output);
  // Bakes hand each RDM to a spill file as it finishes, so memory holds the RDMs in flight;
  // the atlas, noise map and shard are then written from it one RDM at a time.
  SlotSetRecords sets;
  auto spill = RdmSpill::create(a.out);
  if (!spill) return fail("bake", spill.error());
  options.on_rdm_done = [&spill = *spill, &sets,
                         record = options.record_slot_sets](const RdmData& rdm) {
    spill->append(rdm);
    if (record) sets.add(rdm);
  };
  // One device for the RDMs and the face light; creating it is part of the bake's time.
  const auto started = std::chrono::steady_clock::now();
  std::unique_ptr<VulkanBaker> vulkan;
  if (backend == BakeBackend::kVulkan) {
    auto created = VulkanBaker::create(a.device);
    if (!created) {
      if (created_output) removeIfEmpty(a.out);
      return fail("bake", created.error());
    }
    vulkan = std::move(*created);
  }
  auto bc6h = bc6hEncoder(a, vulkan.get());
  auto denoiser = denoiseDevice(a, vulkan.get());
  for (const std::string& error :
       {bc6h ? std::string() : bc6h.error(), denoiser ? std::string() : denoiser.error()}) {
    if (error.empty()) continue;
    if (created_output) removeIfEmpty(a.out);
    return fail("bake", error);
  }
  const double setup =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  auto result = runBake(world, plan.scene, options, vulkan.get(), a, context);
  if (!result) {
    if (created_output) removeIfEmpty(a.out);
    return fail("bake", result.error());
  }
  result->report.seconds += setup;
  if (result->report.cancelled || interrupted()) return cancelled(plan, created_output);
  if (Status s = (*spill)->status(); !s) return fail("bake", s.message() + "; nothing was written");
  std::optional<FaceLightBake> face_light;
  if (a.face_light_spp > 0) {
    std::optional<VulkanFaceLightTracer> on_device;
    if (vulkan) on_device.emplace(*vulkan);
    auto baked =
        bakeFaceLightPhase(world, plan.scene,
                           {a.face_light_spp, a.threads, options.shard_index, options.shard_count,
                            a.quiet, on_device ? &*on_device : nullptr});
    if (!baked) {
      if (created_output) removeIfEmpty(a.out);
      return fail("bake", "face light: " + baked.error() + "; nothing was written");
    }
    face_light = std::move(*baked);
  }
  // The last check: a Ctrl-C from here on is recorded and ignored, for the results are
  // complete and the writes are short and atomic.
  recordInterrupt();
  if (interrupted()) return cancelled(plan, created_output);
  std::unique_ptr<RdmSpill> denoised;
  if (a.denoise) {
    auto filtered = denoiseBake(**spill, a.out, denoiseSettings(a.denoise_scope, plan.scene.bake),
                                {a.threads, denoiser->get(), a.quiet}, context);
    if (!filtered) return fail("bake", filtered.error() + "; nothing was written");
    denoised = std::move(*filtered);
  }
  return writeResults(*result, denoised ? *denoised : **spill, sets, world, plan.scene, options, a,
                      context, face_light ? &*face_light : nullptr, bc6h->encode);
}

}  // namespace

int cmdBake(const Args& args) {
  BakePlan plan;
  if (auto code = planBake(args, plan)) return *code;
  const BakeArgs& a = plan.a;
  bool created_output = false;
  if (Status s = prepareOutputDirectory(a.out, created_output); !s)
    return fail("bake", s.message());
  stopOnInterrupt();  // from here on a Ctrl-C writes nothing
  setExrThreads(a.threads);
  const BakeBackend backend = plan.backend.backend;
  if (!a.quiet)
    std::printf("backend:     %s (%s)\n", bakeBackendName(backend), plan.backend.reason.c_str());
  std::fflush(stdout);
  VoxelWorld world = buildWorld(plan.scene);
  if (auto refused = checkEstimate(world, plan.scene, plan.options, a)) {
    if (created_output) removeIfEmpty(a.out);
    return *refused;
  }
  BakeContext context{&plan.scene, plan.options.target_error, plan.options.max_spp_factor,
                      0,           bakeBackendName(backend),  "cpu"};
  return bakeAndWrite(plan, world, context, created_output);
}

}  // namespace rdm::cli
