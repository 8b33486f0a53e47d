// rdm-viewer --offscreen: renders through the same Renderer without a window.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <numeric>
#include <vector>

#include "atlas_texture.h"
#include "rdm/bake/face_light.h"
#include "rdm/bake/shard.h"
#include "rdm/image/exr_io.h"
#include "rdm/image/png_io.h"
#include "rdm/scene/lighting_fingerprint.h"
#include "run_modes.h"
#include "vk_check.h"

namespace rdm::viewer {
namespace {

struct Timing {
  std::vector<double> ms;
  double mean() const {
    return ms.empty() ? 0.0 : std::accumulate(ms.begin(), ms.end(), 0.0) / double(ms.size());
  }
  double percentile(double q) const {
    if (ms.empty()) return 0.0;
    std::vector<double> s = ms;
    std::sort(s.begin(), s.end());
    return s[std::min(s.size() - 1, size_t(q * double(s.size() - 1) + 0.5))];
  }
};

// Costs are against the flat frame (no RDMs), docs/results.md section 4's comparison.
void printRow(const char* mode, const Timing& t, const Timing& flat) {
  std::printf("| %-13s | %8.3f | %9.3f | %8.3f | %+7.1f %% |\n", mode, t.mean(), t.percentile(0.5),
              t.percentile(0.95), flat.mean() > 0 ? 100.0 * (t.mean() / flat.mean() - 1.0) : 0.0);
}

void printTable(const ViewerOptions& o, const Renderer& r, const Timing& with,
                const Timing& without, const Timing& in_block) {
  std::printf(
      "frame time, %dx%d, %zu frames each (interleaved), scene %s, %d blocks, %d quads drawn\n",
      o.width, o.height, with.ms.size(), o.scene.c_str(), r.sceneData().slots_drawn,
      r.sceneData().quads);
  std::printf("| mode          | mean ms  | median ms | p95 ms   | vs flat   |\n");
  std::printf("|---------------|----------|-----------|----------|-----------|\n");
  printRow("without RDMs", without, without);
  printRow("with RDMs", with, without);
  if (!in_block.ms.empty()) printRow("with in-block", in_block, without);
  std::printf("RDM cost: %+.3f ms per frame (%+.1f %%)\n", with.mean() - without.mean(),
              without.mean() > 0 ? 100.0 * (with.mean() / without.mean() - 1.0) : 0.0);
}

// --compare-rdm: the flat frame, the RDM frame without the in-block term and, when --terms
// asks for it, with it; interleaved frame by frame so the machine's load cancels out.
Status compareFrames(Renderer& r, const Camera& camera, const ViewerOptions& o, int frames) {
  const uint32_t rdm = (o.terms | kTermRdm) & ~uint32_t(kTermInBlock);
  const uint32_t flat = o.terms & ~uint32_t(kTermRdm | kTermInBlock);
  std::vector<std::pair<uint32_t, Timing*>> modes;
  Timing with, without, in_block;
  modes.push_back({rdm, &with});
  modes.push_back({flat, &without});
  if (o.terms & kTermInBlock) modes.push_back({o.terms | kTermRdm, &in_block});
  for (int i = 0; i < frames; ++i) {
    for (auto& [terms, timing] : modes) {
      auto seconds = r.renderFrame(camera, terms);
      if (!seconds) return seconds.status();
      timing->ms.push_back(*seconds * 1e3);
    }
  }
  printTable(o, r, with, without, in_block);
  return Status();
}

Status timeFrames(Renderer& r, const Camera& camera, const ViewerOptions& o, int frames) {
  if (o.compare_rdm) return compareFrames(r, camera, o, frames);
  Timing t;
  for (int i = 0; i < frames; ++i) {
    auto seconds = r.renderFrame(camera, o.terms);
    if (!seconds) return seconds.status();
    t.ms.push_back(*seconds * 1e3);
  }
  std::printf("mean frame time: %.3f ms over %d frame(s) (%dx%d, %s)\n", t.mean(), frames, o.width,
              o.height, rdmState(o, r));
  return Status();
}

}  // namespace

const char* rdmState(const ViewerOptions& o, const Renderer& r) {
  if (!(o.terms & kTermRdm)) return "RDM off (--no-rdm or --terms)";
  return r.layout().entries.empty() ? "RDM off (no atlas)" : "RDM on";
}

Status writeImage8Png(const std::string& path, const Image8& image) {
  return writePng(path, image.width, image.height, image.channels, image.pixels);
}

// The atlas directory's face_light.bin, when it has one, for the scene it was baked from.
Status loadFaceLight(Renderer& renderer, const ViewerOptions& options, const Scene& scene) {
  const std::string path = options.atlas_dir + "/" + kFaceLightFile;
  if (std::error_code ec; !std::filesystem::exists(path, ec)) return Status();
  auto light = readFaceLight(path);
  if (!light) return Status::invalid("--atlas", light.error());
  if (light->scene_digest != faceLightSceneDigest(scene)) {
    if (!options.allow_atlas_mismatch)
      return Status::invalid("--atlas", path + " was not baked from scene '" + options.scene + "'");
    std::printf(
        "face light of another scene version (--allow-atlas-mismatch): edited slots fall back to "
        "the RDMs\n");
  }
  std::printf("face light: %zu faces of %zu slots, %u spp\n", light->faceCount(),
              light->slots.size(), light->spp);
  return renderer.setFaceLight(std::move(*light));
}

// The atlas's lighting fingerprint against the scene's: other light (sun, sky, palette,
// emission, ambient, voxels) is refused as a geometry mismatch is; other bake settings only
// warned of (a draft bake of the same scene is a fine atlas).
Status checkAtlasLighting(const AtlasLayout& layout, const ViewerOptions& options,
                          const Scene& scene) {
  std::vector<std::string> differ =
      lightingDifferences(layout.lighting, lightingFingerprint(scene, scene.bake));
  const bool settings = !differ.empty() && differ.back() == "bake";
  if (settings) {
    differ.pop_back();
    std::printf("atlas baked with other bake settings than scene '%s' (spp, bounces, ...)\n",
                options.scene.c_str());
  }
  if (differ.empty()) return Status();
  std::string parts;
  for (const std::string& d : differ) parts += (parts.empty() ? "" : ", ") + d;
  if (options.allow_atlas_mismatch) {
    std::printf("atlas lit by another %s (--allow-atlas-mismatch)\n", parts.c_str());
    return Status();
  }
  return Status::invalid("--atlas", "--atlas " + options.atlas_dir + " was lit by another " +
                                        parts + " than scene '" + options.scene +
                                        "': bake it again, or --allow-atlas-mismatch");
}

// The atlas directory of --atlas (none without it) and its face light, checked against `scene`.
Status loadAtlasContent(Renderer& renderer, const ViewerOptions& options, const Scene& scene) {
  if (options.atlas_dir.empty()) return Status();
  auto layout = readAtlasLayout(options.atlas_dir);
  if (!layout) return layout.status();
  Status match = checkLayoutMatches(*layout, listRdms(renderer.world(), scene.bake));
  if (!match && options.allow_atlas_mismatch) {
    std::printf("atlas of another scene version (--allow-atlas-mismatch): %s\n",
                match.message().c_str());
  } else if (Status s = match; !s)
    return Status::invalid("--atlas", "--atlas " + options.atlas_dir +
                                          " was not baked from scene '" + options.scene +
                                          "': " + s.message());
  RDM_TRY(checkAtlasLighting(*layout, options, scene));
  RDM_TRY(renderer.loadAtlas(options.atlas_dir, std::move(*layout)));  // page by page
  const AtlasTexture& texture = renderer.atlas();
  std::printf("atlas texture: %s, %.1f MB on the device\n", atlasPrecisionName(texture.precision()),
              double(texture.deviceBytes()) / 1e6);
  return loadFaceLight(renderer, options, scene);
}

Expected<size_t> loadViewerContent(Renderer& renderer, const ViewerOptions& options, Scene& scene) {
  auto loaded = loadSceneByNameOrPath(options.scene);
  if (!loaded) return loaded.status();
  scene = std::move(*loaded);
  auto camera = findCamera(scene, options.camera);
  if (!camera) return camera.status();
  RDM_TRY(renderer.setScene(scene));
  RDM_TRY(loadAtlasContent(renderer, options, scene));
  return *camera;
}

int runOffscreen(const ViewerOptions& o) {
  ContextOptions context_options;
  context_options.device = o.device;
  auto context = VulkanContext::create(context_options);
  if (!context) return std::fprintf(stderr, "rdm-viewer: %s\n", context.error().c_str()), 1;
  auto renderer = Renderer::create(**context, rendererOptions(o, o.width, o.height));
  if (!renderer) return std::fprintf(stderr, "rdm-viewer: %s\n", renderer.error().c_str()), 1;
  Renderer& r = **renderer;
  Scene scene;
  auto camera_index = loadViewerContent(r, o, scene);
  if (!camera_index)
    return std::fprintf(stderr, "rdm-viewer: %s\n", camera_index.error().c_str()), 1;
  std::printf("device: %s\n%s\n", (*context)->deviceDescription().c_str(), rdmState(o, r));
  const Camera& camera = scene.cameras[*camera_index];
  auto warmup = r.renderFrame(camera, o.terms);  // first use of each pipeline is slower
  if (!warmup) return std::fprintf(stderr, "rdm-viewer: %s\n", warmup.error().c_str()), 1;
  if (Status s = timeFrames(r, camera, o, o.frames < 0 ? 1 : o.frames); !s.ok()) {
    return std::fprintf(stderr, "rdm-viewer: %s\n", s.message().c_str()), 1;
  }
  if (o.compare_rdm || o.aa_frames > 1) {  // the written image: the requested terms, averaged
    r.setAccumulationLimit(o.aa_frames);
    for (int i = 0; i < o.aa_frames; ++i) {
      if (auto again = r.renderFrame(camera, o.terms); !again) {
        return std::fprintf(stderr, "rdm-viewer: %s\n", again.error().c_str()), 1;
      }
    }
    if (o.aa_frames > 1) std::printf("anti-aliased: %d jittered frames averaged\n", o.aa_frames);
  }
  auto ldr = r.readLdr();
  if (!ldr) return std::fprintf(stderr, "rdm-viewer: %s\n", ldr.error().c_str()), 1;
  if (Status s = writeImage8Png(o.offscreen_png, *ldr); !s.ok()) {
    return std::fprintf(stderr, "rdm-viewer: %s\n", s.message().c_str()), 1;
  }
  if (!o.exr_path.empty()) {
    auto hdr = r.readHdr();
    if (!hdr) return std::fprintf(stderr, "rdm-viewer: %s\n", hdr.error().c_str()), 1;
    if (Status s = writeExr(o.exr_path, *hdr, kRgbChannels); !s.ok()) {
      return std::fprintf(stderr, "rdm-viewer: %s\n", s.message().c_str()), 1;
    }
  }
  return 0;
}

}  // namespace rdm::viewer
