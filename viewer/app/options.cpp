#include "options.h"

#include <CLI/CLI.hpp>

#include <sstream>

#include "gpu_layout.h"

namespace rdm::viewer {
namespace {

// The command line of rdm-viewer: every option bound to `options` (and to `terms_list`,
// `mode` and `no_rdm`, converted after parsing). --help prints each with its default.
struct CommandLine {
  CLI::App app{"Real-time RDM shading of a voxel scene, offscreen or in a window", "rdm-viewer"};
  ViewerOptions options;
  std::string terms_list = "all", mode = "exact";
  bool no_rdm = false;

  CommandLine();
};

CommandLine::CommandLine() {
  ViewerOptions& o = options;
  app.option_defaults()->always_capture_default();
  app.add_option("--scene", o.scene, "built-in scene name or scene JSON file");
  app.add_option("--camera", o.camera, "scene camera: index or name")->type_name("INDEX|NAME");
  app.add_option("--atlas", o.atlas_dir, "atlas directory (atlas.exr + index.json) of `rdm bake`");
  app.add_option("--width", o.width, "image width")->check(CLI::Range(1, 16384));
  app.add_option("--height", o.height, "image height")->check(CLI::Range(1, 16384));
  app.add_option("--offscreen", o.offscreen_png,
                 "render without a window and write the tone-mapped image (PNG)");
  app.add_option("--exr", o.exr_path, "offscreen: also write the HDR (pre-tone-map) image");
  app.add_option("--frames", o.frames,
                 "frames to render (offscreen: timed frames, 1 if not given; window: exit after "
                 "N, none if not given)")
      ->check(CLI::Range(1, 1 << 24));
  app.add_flag("--compare-rdm", o.compare_rdm,
               "offscreen: time N frames with and without RDMs, interleaved, print a table");
  app.add_option("--screenshot", o.screenshot_png, "window: write the last frame as PNG on exit");
  app.add_flag("--no-rdm", no_rdm, "flat ambient instead of the RDMs (docs/spec.md section 7)");
  app.add_option(
      "--terms", terms_list,
      "comma list of rdm,diffuse,specular,sun,shadows,emission,background,in-block,face-light,"
      "block-blend (or all)");
  app.add_option("--server", o.server_url, "live rebakes from an `rdm serve` daemon at URL");
  app.add_option("--live-mode", mode, "incremental mode of live rebakes: exact or fast");
  app.add_option("--face-light", o.face_light_spp,
                 "with --server: every job also bakes the light of every voxel face at N samples "
                 "(the face-light term; edits update it in the viewer; 0: none)")
      ->check(CLI::Range(0, 65536))
      ->default_str("the scene's bake.face_light_spp");
  app.add_option("--live-divisor", o.live_divisor,
                 "while a rebake runs, shade 1/N of the width and height (1: always full)")
      ->check(CLI::Range(1, 4));
  app.add_option("--aa", o.aa_frames,
                 "anti-aliasing: average N jittered frames while the view is still (1: off; "
                 "0: the mode's default, 16 in a window, 1 offscreen)")
      ->check(CLI::Range(0, kMaxAccumulatedFrames));
  app.add_option("--device", o.device,
                 "Vulkan device by index or name substring (default: the best GPU, else the "
                 "first CPU device; docs/vulkan.md)");
  app.add_option("--edit", o.edit,
                 "with --offscreen: bake (on --server, or in-process from --atlas or from "
                 "scratch), apply one edit, time the rebake "
                 "(\"remove I,J,K\", \"add I,J,K BLOCK [ROT]\", \"paint I,J,K X,Y,Z PALETTE\")");
  app.add_option("--edit-report", o.edit_report,
                 "where the edit's timings go as JSON (default: OUT.png's name + .json)");
  app.add_flag("--allow-atlas-mismatch", o.allow_atlas_mismatch,
               "show an atlas baked for another version of the scene (stale RDMs on purpose)");
  app.add_flag("--float-atlas", o.float_atlas,
               "keep the atlas at 32-bit float on the device (twice the memory of the default "
               "half; the reference the half atlas is compared with)");
  app.add_option("--bc6h-texture", o.bc6h_texture,
                 "a bc6h atlas on the device: its blocks as they are (stored; 3 bytes a texel "
                 "with Z), decoded on the CPU into the half texture (decoded; 8 bytes), or auto: "
                 "stored on a GPU that samples BC6H, decoded on a CPU device such as lavapipe, "
                 "where sampling BC6H costs 2.5-3x the frame (docs/bc6h.md)")
      ->check(CLI::IsMember({"auto", "stored", "decoded"}));
  app.add_option("--tool", o.tool, "window: the edit tool selected at start (left click)")
      ->check(CLI::IsMember({"none", "add", "remove", "carve", "paint"}));
  app.add_option("--min-frame-ms", o.min_frame_ms,
                 "window: every frame takes at least N ms (sleeps after presenting; for tests "
                 "that input counts however slow the frames are)")
      ->check(CLI::Range(0, 60000));
  app.add_flag("--version", o.version, "print the build id (as `rdm --version`) and exit");
  app.allow_extras();  // reported by parseViewerOptions as "unknown option", naming it
}

// The combinations that make no sense, and the defaults that depend on the mode.
Status finish(ViewerOptions& o) {
  if (!o.exr_path.empty() && o.offscreen_png.empty())
    return Status::error("--exr needs --offscreen");
  if (o.compare_rdm && o.offscreen_png.empty())
    return Status::error("--compare-rdm needs --offscreen");
  if (o.face_light_spp >= 0 && o.server_url.empty())
    return Status::error("--face-light needs --server (an `rdm bake --face-light` atlas has it)");
  if (!o.edit.empty() && o.offscreen_png.empty()) return Status::error("--edit needs --offscreen");
  if (!o.server_url.empty() && !o.offscreen_png.empty() && o.edit.empty())
    return Status::error("--server with --offscreen needs --edit (the scripted live rebake)");
  if (!o.edit_report.empty() && o.edit.empty()) return Status::error("--edit-report needs --edit");
  if (!o.offscreen_png.empty() && (o.tool != "none" || o.min_frame_ms > 0))
    return Status::error("--tool and --min-frame-ms are for the window, not --offscreen");
  if (!o.edit.empty() && o.edit_report.empty()) {
    const size_t dot = o.offscreen_png.rfind('.');
    o.edit_report =
        o.offscreen_png.substr(0, dot == std::string::npos ? o.offscreen_png.size() : dot) +
        ".json";
  }
  if (o.aa_frames == 0) o.aa_frames = o.offscreen_png.empty() ? kWindowAccumulatedFrames : 1;
  return Status();
}

}  // namespace

Expected<uint32_t> parseTerms(const std::string& list) {
  const std::pair<const char*, uint32_t> kNames[] = {{"rdm", kTermRdm},
                                                     {"diffuse", kTermDiffuse},
                                                     {"specular", kTermSpecular},
                                                     {"sun", kTermSun},
                                                     {"shadows", kTermShadows},
                                                     {"emission", kTermEmission},
                                                     {"background", kTermBackground},
                                                     {"in-block", kTermInBlock},
                                                     {"face-light", kTermFaceLight},
                                                     {"block-blend", kTermBlockBlend},
                                                     {"face-light-filter", kTermFaceLightFilter},
                                                     {"all", kTermDefault},
                                                     {"none", 0}};
  uint32_t bits = 0;
  std::stringstream in(list);
  std::string name;
  while (std::getline(in, name, ',')) {
    bool found = false;
    for (const auto& [n, bit] : kNames) {
      if (name == n) bits |= bit, found = true;
    }
    if (!found) return Status::error("--terms: unknown term '" + name + "'");
  }
  return bits;
}

std::string viewerUsage() {
  return CommandLine().app.help();
}

Expected<ViewerOptions> parseViewerOptions(int argc, char** argv) {
  CommandLine line;
  CLI::App& app = line.app;
  ViewerOptions& o = line.options;
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp&) {
    o.help = true;
    return o;
  } catch (const CLI::ParseError& e) {
    return Status::error(e.what());
  }
  if (const std::vector<std::string> extra = app.remaining(); !extra.empty()) {
    const std::string& arg = extra.front();
    return Status::error(arg.rfind("-", 0) == 0 ? "unknown option '" + arg + "' (see --help)"
                                                : "unknown argument '" + arg + "'");
  }
  auto terms = parseTerms(line.terms_list);
  if (!terms) return terms.status();
  o.terms = *terms & (line.no_rdm ? ~uint32_t(kTermRdm) : ~0u);
  if (!parseMode(line.mode, o.live_mode) || o.live_mode == BakeMode::kFull)
    return Status::error("--live-mode: expected exact or fast, got '" + line.mode + "'");
  if (Status s = finish(o); !s) return s;
  return o;
}

}  // namespace rdm::viewer
