// exr_tool mean OUT.exr IN.exr...       per-pixel mean of RGB EXRs of one size (two independent
//                                        N-spp renders -> one 2N-spp reference)
// exr_tool thumb IN.exr OUT.png [--scale K] [--crop X Y W H]
//                                        Reinhard + sRGB (as `rdm flip` and the viewer tone-map),
//                                        box-filtered down by K (default 1), as an RGB PNG
// Exit status 1 on unreadable input, size mismatch or a non-finite value; 2 on usage errors.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "rdm/image/exr_io.h"
#include "rdm/image/flip.h"
#include "rdm/image/png_io.h"
#include "rdm/image/tonemap.h"

namespace {

bool readRgb(const std::string& path, rdm::Image& image) {
  auto read = rdm::readFiniteExr(path, rdm::kRgbChannels);
  if (!read) return std::fprintf(stderr, "exr_tool: %s\n", read.error().c_str()), false;
  image = std::move(*read);
  return true;
}

int mean(const std::string& out, const std::vector<std::string>& inputs) {
  rdm::Image sum;
  const float n = float(inputs.size());
  for (size_t i = 0; i < inputs.size(); ++i) {
    rdm::Image image;
    if (!readRgb(inputs[i], image)) return 1;
    if (i == 0) {
      sum = rdm::Image(image.width, image.height, 3);
    } else if (image.width != sum.width || image.height != sum.height) {
      return std::fprintf(stderr, "exr_tool: %s has a different size\n", inputs[i].c_str()), 1;
    }
    for (size_t k = 0; k < sum.pixels.size(); ++k) sum.pixels[k] += image.pixels[k] / n;
  }
  if (auto s = rdm::writeExr(out, sum, rdm::kRgbChannels); !s) {
    return std::fprintf(stderr, "exr_tool: %s\n", s.message().c_str()), 1;
  }
  return 0;
}

// The rectangle {x, y, w, h} of `image`; false (with a message) when it leaves the image.
bool cropImage(rdm::Image& image, const std::vector<int>& rect) {
  const int x0 = rect[0], y0 = rect[1], w = rect[2], h = rect[3];
  if (x0 < 0 || y0 < 0 || w < 1 || h < 1 || x0 + w > image.width || y0 + h > image.height) {
    std::fprintf(stderr, "exr_tool: --crop %d %d %d %d leaves the %dx%d image\n", x0, y0, w, h,
                 image.width, image.height);
    return false;
  }
  rdm::Image cropped(w, h, image.channels);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < image.channels; ++c) cropped.at(x, y, c) = image.at(x0 + x, y0 + y, c);
  image = std::move(cropped);
  return true;
}

int thumb(const std::string& in, const std::string& out, int scale, const std::vector<int>& crop) {
  rdm::Image image;
  if (!readRgb(in, image)) return 1;
  if (!crop.empty() && !cropImage(image, crop)) return 1;
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
  if (auto s = rdm::writePng(out, w, h, 3, px); !s) {
    return std::fprintf(stderr, "exr_tool: %s\n", s.message().c_str()), 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app("EXR helpers of the evaluation harness", "exr_tool");
  app.option_defaults()->always_capture_default();
  app.require_subcommand(1);
  std::string out, in;
  std::vector<std::string> inputs;
  int scale = 1;
  CLI::App* mean_cmd = app.add_subcommand("mean", "per-pixel mean of RGB EXRs of one size");
  mean_cmd->add_option("OUT.exr", out, "the mean")->required();
  mean_cmd->add_option("IN.exr", inputs, "the images")->required();
  CLI::App* thumb_cmd = app.add_subcommand("thumb", "Reinhard + sRGB PNG, box-filtered down");
  thumb_cmd->add_option("IN.exr", in, "the image")->required();
  thumb_cmd->add_option("OUT.png", out, "the thumbnail")->required();
  thumb_cmd->add_option("--scale", scale, "box filter width")->check(CLI::Range(1, 64));
  std::vector<int> crop;
  thumb_cmd->add_option("--crop", crop, "X Y W H: only this rectangle (before --scale)")
      ->expected(4);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  return mean_cmd->parsed() ? mean(out, inputs) : thumb(in, out, scale, crop);
}
