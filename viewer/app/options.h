// Command line of rdm-viewer.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "rdm/bake/rebake_selection.h"
#include "rdm/base/status.h"

namespace rdm::viewer {

inline constexpr int kWindowAccumulatedFrames = 16;
inline constexpr int kMaxAccumulatedFrames = 1024;

struct ViewerOptions {
  std::string scene = "chess";
  std::string camera = "0";  // index or name (rdm::findCamera, once the scene is loaded)
  std::string atlas_dir;
  int width = 1280, height = 720;
  std::string offscreen_png, exr_path, screenshot_png, server_url;
  int frames = -1;  // -1: default (1 offscreen, unlimited in a window)
  bool compare_rdm = false;
  bool help = false, version = false;
  uint32_t terms = 0;  // Term bits
  BakeMode live_mode = BakeMode::kExact;
  // --server: samples per face of the daemon's face light; 0: none, -1: the scene's.
  int face_light_spp = -1;
  int live_divisor = 2;  // Renderer::setResolutionDivisor while a rebake is in flight
  int aa_frames = 0;     // Renderer::setAccumulationLimit; 0 until parsed: the mode's default
  std::string device;    // ContextOptions::device
  std::string edit, edit_report;
  bool allow_atlas_mismatch = false;
  bool float_atlas = false;  // RGBA32F atlas on the device (the reference for the half one)
  std::string bc6h_texture = "auto";  // RendererOptions::bc6h_texture
  std::string tool = "none";          // window: the edit tool selected at start
  int min_frame_ms = 0;  // window: each frame takes at least this long (tests of input)
};

// Parses argv (CLI11); errors name the offending argument. --help sets `help`.
Expected<ViewerOptions> parseViewerOptions(int argc, char** argv);
// Every option with its default: the --help text.
std::string viewerUsage();
// Term bits of a comma list such as "rdm,sun,shadows".
Expected<uint32_t> parseTerms(const std::string& list);

}  // namespace rdm::viewer
