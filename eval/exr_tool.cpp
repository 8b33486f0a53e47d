// exr_tool mean OUT.exr IN.exr...       per-pixel mean of RGB EXRs of one size (two independent
//                                        N-spp renders -> one 2N-spp reference)
// exr_tool thumb IN.exr OUT.png [--scale K]
//                                        Reinhard + sRGB (as `rdm flip` and the viewer tone-map),
//                                        box-filtered down by K (default 1), as an RGB PNG
// Exit status 1 on unreadable input, size mismatch or a non-finite value; 2 on usage errors.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "rdm/exr_io.h"
#include "rdm/flip.h"
#include "rdm/png_io.h"

namespace {

int usage() {
  std::fprintf(
      stderr,
      "usage: exr_tool mean OUT.exr IN.exr...\n       exr_tool thumb IN.exr OUT.png [--scale K]\n");
  return 2;
}

bool readRgb(const std::string& path, rdm::Image& image) {
  auto read = rdm::readExr(path, rdm::kRgbChannels);
  if (!read) return std::fprintf(stderr, "exr_tool: %s\n", read.error().c_str()), false;
  image = std::move(*read);
  for (float v : image.pixels) {
    if (!std::isfinite(v))
      return std::fprintf(stderr, "exr_tool: non-finite value in %s\n", path.c_str()), false;
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) return usage();
  const std::string verb = argv[1];
  if (verb == "mean") {
    if (argc < 4) return usage();
    rdm::Image sum;
    const int n = argc - 3;
    for (int i = 3; i < argc; ++i) {
      rdm::Image image;
      if (!readRgb(argv[i], image)) return 1;
      if (i == 3) {
        sum = rdm::Image(image.width, image.height, 3);
      } else if (image.width != sum.width || image.height != sum.height) {
        return std::fprintf(stderr, "exr_tool: %s has a different size\n", argv[i]), 1;
      }
      for (size_t k = 0; k < sum.pixels.size(); ++k) sum.pixels[k] += image.pixels[k] / float(n);
    }
    if (auto s = rdm::writeExr(argv[2], sum, rdm::kRgbChannels); !s) {
      return std::fprintf(stderr, "exr_tool: %s\n", s.message().c_str()), 1;
    }
    return 0;
  }
  if (verb == "thumb") {
    if (argc != 4 && argc != 6) return usage();
    int scale = 1;
    if (argc == 6) {
      if (std::strcmp(argv[4], "--scale") != 0) return usage();
      scale = std::atoi(argv[5]);
      if (scale < 1 || scale > 64) return usage();
    }
    rdm::Image image;
    if (!readRgb(argv[2], image)) return 1;
    rdm::Image ldr = rdm::tonemapReinhardSrgb(image);
    const int w = std::max(1, image.width / scale), h = std::max(1, image.height / scale);
    std::vector<uint8_t> px(size_t(w) * h * 3);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        for (int c = 0; c < 3; ++c) {
          double acc = 0;
          int cnt = 0;
          for (int dy = 0; dy < scale; ++dy)
            for (int dx = 0; dx < scale; ++dx) {
              const int sx = x * scale + dx, sy = y * scale + dy;
              if (sx < image.width && sy < image.height) acc += ldr.at(sx, sy, c), ++cnt;
            }
          px[(size_t(y) * w + x) * 3 + c] =
              uint8_t(std::lround(std::clamp(acc / cnt, 0.0, 1.0) * 255.0));
        }
    if (auto s = rdm::writePng(argv[3], w, h, 3, px); !s) {
      return std::fprintf(stderr, "exr_tool: %s\n", s.message().c_str()), 1;
    }
    return 0;
  }
  return usage();
}
