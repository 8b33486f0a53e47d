#include "options.h"

#include <cstdlib>
#include <sstream>

#include "gpu_layout.h"

namespace rdm::viewer {
namespace {

bool parseInt(const std::string& text, int lo, int hi, int& out) {
  char* end = nullptr;
  const long v = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || v < lo || v > hi) return false;
  out = int(v);
  return true;
}

bool takesValue(const std::string& arg) {
  for (const char* name : {"--scene", "--atlas", "--offscreen", "--exr", "--screenshot", "--server",
                           "--terms", "--camera", "--width", "--height", "--frames", "--live-mode",
                           "--edit", "--edit-report", "--live-divisor", "--device", "--aa"}) {
    if (arg == name) return true;
  }
  return false;
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
                                                     {"all", kTermAll},
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

Expected<ViewerOptions> parseViewerOptions(int argc, char** argv) {
  ViewerOptions o;
  o.terms = kTermAll;
  bool no_rdm = false;
  std::optional<uint32_t> terms;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&](std::string& out) -> bool {
      if (i + 1 >= argc) return false;
      out = argv[++i];
      return true;
    };
    std::string v;
    if (arg == "--help" || arg == "-h") {
      o.help = true;
    } else if (arg == "--no-rdm") {
      no_rdm = true;
    } else if (arg == "--compare-rdm") {
      o.compare_rdm = true;
    } else if (arg == "--allow-atlas-mismatch") {
      o.allow_atlas_mismatch = true;
    } else if (!takesValue(arg)) {
      return Status::error(arg.rfind("-", 0) == 0 ? "unknown option '" + arg + "' (see --help)"
                                                  : "unknown argument '" + arg + "'");
    } else if (!value(v)) {
      return Status::error(arg + " needs a value");
    } else if (arg == "--live-mode") {
      if (!parseMode(v, o.live_mode) || o.live_mode == BakeMode::kFull)
        return Status::error("--live-mode: expected exact or fast, got '" + v + "'");
    } else if (arg == "--edit") {
      o.edit = v;
    } else if (arg == "--edit-report") {
      o.edit_report = v;
    } else if (arg == "--scene") {
      o.scene = v;
    } else if (arg == "--atlas") {
      o.atlas_dir = v;
    } else if (arg == "--offscreen") {
      o.offscreen_png = v;
    } else if (arg == "--exr") {
      o.exr_path = v;
    } else if (arg == "--screenshot") {
      o.screenshot_png = v;
    } else if (arg == "--server") {
      o.server_url = v;
    } else if (arg == "--terms") {
      auto t = parseTerms(v);
      if (!t) return t.status();
      terms = *t;
    } else if (arg == "--camera") {
      if (!parseInt(v, 0, 1 << 20, o.camera))
        return Status::error("--camera: expected an index, got '" + v + "'");
    } else if (arg == "--width") {
      if (!parseInt(v, 1, 16384, o.width))
        return Status::error("--width: expected 1..16384, got '" + v + "'");
    } else if (arg == "--height") {
      if (!parseInt(v, 1, 16384, o.height))
        return Status::error("--height: expected 1..16384, got '" + v + "'");
    } else if (arg == "--device") {
      o.device = v;
    } else if (arg == "--live-divisor") {
      if (!parseInt(v, 1, 4, o.live_divisor))
        return Status::error("--live-divisor: expected 1..4, got '" + v + "'");
    } else if (arg == "--aa") {
      if (!parseInt(v, 1, kMaxAccumulatedFrames, o.aa_frames))
        return Status::error("--aa: expected 1.." + std::to_string(kMaxAccumulatedFrames) +
                             " frames, got '" + v + "'");
    } else if (arg == "--frames") {
      if (!parseInt(v, 1, 1 << 24, o.frames))
        return Status::error("--frames: expected a positive count, got '" + v + "'");
    } else {
      return Status::error("unknown option '" + arg + "'");
    }
  }
  if (terms) o.terms = *terms;
  if (o.aa_frames == 0) o.aa_frames = o.offscreen_png.empty() ? kWindowAccumulatedFrames : 1;
  if (no_rdm) o.terms &= ~uint32_t(kTermRdm);
  if (!o.exr_path.empty() && o.offscreen_png.empty())
    return Status::error("--exr needs --offscreen");
  if (o.compare_rdm && o.offscreen_png.empty())
    return Status::error("--compare-rdm needs --offscreen");
  if (!o.edit.empty() && (o.server_url.empty() || o.offscreen_png.empty()))
    return Status::error("--edit needs --server and --offscreen");
  if (!o.server_url.empty() && !o.offscreen_png.empty() && o.edit.empty())
    return Status::error("--server with --offscreen needs --edit (the scripted live rebake)");
  if (!o.edit_report.empty() && o.edit.empty()) return Status::error("--edit-report needs --edit");
  if (!o.edit.empty() && o.edit_report.empty()) {
    const size_t dot = o.offscreen_png.rfind('.');
    o.edit_report =
        o.offscreen_png.substr(0, dot == std::string::npos ? o.offscreen_png.size() : dot) +
        ".json";
  }
  return o;
}

}  // namespace rdm::viewer
