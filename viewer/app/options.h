// Command line of rdm-viewer.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "rdm/rebake_selection.h"
#include "rdm/status.h"

namespace rdm::viewer {

inline constexpr const char* kViewerUsage =
    "usage: rdm-viewer [--scene NAME|FILE.json] [--camera N] [--atlas DIR] [--width W] [--height "
    "H]\n"
    "                  [--offscreen OUT.png [--exr OUT.exr] [--compare-rdm]] [--frames N]\n"
    "                  [--screenshot OUT.png] [--no-rdm] [--terms LIST] [--server URL]\n"
    "  --offscreen   render without a window and write the tone-mapped image\n"
    "  --exr         also write the HDR (pre-tone-map) image\n"
    "  --frames N    frames to render (offscreen: timed frames, default 1; window: exit after N)\n"
    "  --compare-rdm offscreen: time N frames with and without RDMs, interleaved, print a table\n"
    "  --screenshot  window: write the last frame as PNG when exiting\n"
    "  --no-rdm      flat ambient instead of the RDMs (docs/spec.md section 7's baseline)\n"
    "  --terms LIST  comma list of rdm,diffuse,specular,sun,shadows,emission,background\n"
    "  --server URL  live rebakes from an rdm bake daemon\n"
    "  --live-mode M incremental mode of live rebakes: exact (default) or fast\n"
    "  --device D    Vulkan device by index or name substring (default: the best GPU, else\n"
    "                the first CPU device; docs/vulkan.md)\n"
    "  --live-divisor N  while a rebake runs, shade 1/N of the width and height (1..4,\n"
    "                default 2; 1: always full resolution)\n"
    "  --edit EDIT   with --server and --offscreen: bake, apply one edit, time the live rebake\n"
    "                (\"remove I,J,K\", \"add I,J,K BLOCK [ROT]\", \"paint I,J,K X,Y,Z PALETTE\")\n"
    "  --edit-report FILE  where the edit's timings go as JSON (default: OUT.png's name + .json)\n"
    "  --aa N        anti-aliasing: average N jittered frames while the view is still\n"
    "                (1: off; default 16 in a window, 1 offscreen)\n"
    "  --allow-atlas-mismatch  show an atlas baked for another version of the scene (stale\n"
    "                RDMs on purpose); without it such an atlas is refused\n";

inline constexpr int kWindowAccumulatedFrames = 16;
inline constexpr int kMaxAccumulatedFrames = 1024;

struct ViewerOptions {
  std::string scene = "chess";
  int camera = 0;
  std::string atlas_dir;
  int width = 1280, height = 720;
  std::string offscreen_png, exr_path, screenshot_png, server_url;
  int frames = -1;  // -1: default (1 offscreen, unlimited in a window)
  bool compare_rdm = false;
  bool help = false;
  uint32_t terms = 0;  // Term bits
  BakeMode live_mode = BakeMode::kExact;
  int live_divisor = 2;  // Renderer::setResolutionDivisor while a rebake is in flight
  int aa_frames = 0;     // Renderer::setAccumulationLimit; 0 until parsed: the mode's default
  std::string device;    // ContextOptions::device
  std::string edit, edit_report;
  bool allow_atlas_mismatch = false;
};

// Parses argv; errors name the offending argument.
Expected<ViewerOptions> parseViewerOptions(int argc, char** argv);
// Term bits of a comma list such as "rdm,sun,shadows".
Expected<uint32_t> parseTerms(const std::string& list);

}  // namespace rdm::viewer
