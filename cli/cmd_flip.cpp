// `rdm flip REFERENCE TEST [--ppd P] [--hdr] [--map out.png]`: FLIP between two linear HDR
// EXR images (docs/spec.md section 7). Both are tone-mapped with Reinhard + sRGB for LDR-FLIP;
// --hdr adds HDR-FLIP of the untonemapped pair.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "commands.h"
#include "output_check.h"
#include "rdm/base/status.h"
#include "rdm/image/exr_io.h"
#include "rdm/image/flip.h"
#include "rdm/image/image.h"
#include "rdm/image/png_io.h"
#include "rdm/image/tonemap.h"

namespace rdm::cli {
namespace {

constexpr const char* kUsage =
    "usage: rdm flip REFERENCE TEST [--ppd P] [--hdr] [--map out.png]\n"
    "  REFERENCE, TEST  linear HDR OpenEXR images with channels R, G, B, same size\n"
    "  --ppd P          pixels per degree of visual angle (default 67.02)\n"
    "  --hdr            also report HDR-FLIP of the untonemapped pair\n"
    "  --map out.png    write the LDR-FLIP error map (magma, with a legend) as PNG\n"
    "Prints the mean LDR-FLIP of the Reinhard + sRGB tone-mapped pair.\n";

struct Options {
  std::string reference, test, map_path;
  double ppd = kDefaultPixelsPerDegree;
  bool hdr = false;
};

int usageError(const std::string& message) {
  std::fprintf(stderr, "rdm flip: %s\n%s", message.c_str(), kUsage);
  return 2;
}

std::optional<double> parsePositive(const std::string& text) {
  try {
    size_t used = 0;
    double v = std::stod(text, &used);
    if (used == text.size() && std::isfinite(v) && v > 0.0) return v;
  } catch (const std::exception&) {
  }
  return std::nullopt;
}

// Returns the exit code for a usage error, or 0 when `options` is filled; -1 for --help.
int parseArgs(const Args& args, Options& options) {
  std::vector<std::string> positional;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& arg = args[i];
    bool has_value = i + 1 < args.size();
    if (arg == "--help" || arg == "-h") return -1;
    if (arg == "--hdr") {
      options.hdr = true;
    } else if (arg == "--ppd" || arg == "--map") {
      if (!has_value) return usageError(arg + " needs a value");
      const std::string& value = args[++i];
      if (arg == "--map") {
        options.map_path = value;
      } else if (auto ppd = parsePositive(value)) {
        options.ppd = *ppd;
      } else {
        return usageError("--ppd must be a positive number, got '" + value + "'");
      }
    } else if (arg.size() > 1 && arg[0] == '-') {
      return usageError("unknown option '" + arg + "'");
    } else {
      positional.push_back(arg);
    }
  }
  if (positional.size() != 2) return usageError("expected REFERENCE and TEST images");
  options.reference = positional[0];
  options.test = positional[1];
  return 0;
}

bool loadImage(const char* role, const std::string& path, Image& image) {
  Expected<Image> read = readFiniteExr(path, kRgbChannels);
  if (!read) {
    std::fprintf(stderr, "rdm flip: cannot use %s image '%s': %s\n", role, path.c_str(),
                 read.error().c_str());
    return false;
  }
  image = std::move(*read);
  return true;
}

bool writeMap(const std::string& path, const Image& error_map) {
  Image8 map = appendColorLegend(magmaColorMap(error_map));
  Status status = writePng(path, map.width, map.height, map.channels, map.pixels);
  if (!status) std::fprintf(stderr, "rdm flip: %s\n", status.message().c_str());
  return status.ok();
}

int run(const Options& options) {
  if (!options.map_path.empty()) {
    if (Status s = checkOutputFile(options.map_path); !s) {
      std::fprintf(stderr, "rdm flip: --map %s\n", s.message().c_str());
      return 1;
    }
  }
  Image reference, test;
  if (!loadImage("reference", options.reference, reference)) return 1;
  if (!loadImage("test", options.test, test)) return 1;
  if (reference.width != test.width || reference.height != test.height) {
    std::fprintf(stderr, "rdm flip: size mismatch: reference '%s' is %dx%d, test '%s' is %dx%d\n",
                 options.reference.c_str(), reference.width, reference.height, options.test.c_str(),
                 test.width, test.height);
    return 1;
  }
  FlipResult ldr =
      computeLdrFlip(tonemapReinhardSrgb(reference), tonemapReinhardSrgb(test), options.ppd);
  std::printf("mean LDR-FLIP: %.6f\n", ldr.mean);
  if (options.hdr) {
    std::printf("mean HDR-FLIP: %.6f\n", computeHdrFlip(reference, test, options.ppd).mean);
  }
  std::fflush(stdout);
  if (!options.map_path.empty() && !writeMap(options.map_path, ldr.error_map)) return 1;
  return 0;
}

}  // namespace

int cmdFlip(const Args& args) {
  Options options;
  int parsed = parseArgs(args, options);
  if (parsed == -1) {
    std::fputs(kUsage, stdout);
    return 0;
  }
  if (parsed != 0) return parsed;
  try {
    return run(options);
  } catch (const std::exception& e) {  // out of memory, thread creation
    std::fprintf(stderr, "rdm flip: %s\n", e.what());
    return 1;
  }
}

}  // namespace rdm::cli
