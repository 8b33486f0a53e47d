#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "atlas_input.h"
#include "cli_app.h"
#include "commands.h"
#include "number_checks.h"
#include "output_check.h"
#include "rdm/atlas/atlas.h"
#include "rdm/atlas/noise_map.h"
#include "rdm/image/exr_io.h"
#include "rdm/image/flip.h"
#include "rdm/image/png_io.h"
#include "rdm/image/tonemap.h"

namespace rdm::cli {
namespace {

namespace fs = std::filesystem;

std::vector<uint8_t> toBytes(const Image& mapped) {
  std::vector<uint8_t> bytes(mapped.pixels.size());
  for (size_t i = 0; i < bytes.size(); ++i)
    bytes[i] = uint8_t(std::lround(std::clamp(mapped.pixels[i], 0.0f, 1.0f) * 255.0f));
  return bytes;
}

// Channel `channel` of `texels` shown as z / (1 + z); "no hit" depths (>= 1e4) are black.
Image depthImage(const Image& texels, int channel) {
  Image view(texels.width, texels.height, 3);
  const size_t pixels = size_t(texels.width) * size_t(texels.height);
  for (size_t i = 0; i < pixels; ++i) {
    const float v = texels.pixels[i * size_t(texels.channels) + size_t(channel)];
    const float shown = v >= 1e4f || !(v >= 0.0f) ? 0.0f : v / (1.0f + v);
    for (int c = 0; c < 3; ++c) view.pixels[i * 3 + size_t(c)] = shown;
  }
  return view;
}

Expected<Image> depthView(const std::string& in) {
  auto z = readExr(in, {"Z"});
  if (!z) return z;
  return depthImage(*z, 0);
}

// Page 0 of the bc6h atlas directory `in`, decoded: R, G, B, or Z as depthImage shows it.
Expected<Image> bc6hPageView(const std::string& in, const AtlasLayout& layout, bool depth) {
  auto page = readBc6hAtlasPage(in, layout, 0);
  if (!page) return page.status();
  restoreRadiance(layout, 0, *page);
  if (depth) return depthImage(*page, 3);
  Image rgb(page->width, page->height, 3);
  for (size_t i = 0; i < rgb.pixels.size() / 3; ++i)
    for (size_t c = 0; c < 3; ++c) rgb.pixels[i * 3 + c] = page->pixels[i * 4 + c];
  return rgb;
}

// The colour or depth image `in` names: an EXR file, or page 0 of an atlas directory.
Expected<Image> previewImage(const std::string& in, bool depth) {
  if (fs::is_directory(in) && !fs::exists(fs::path(in) / "atlas.exr")) {
    auto layout = readAtlasLayout(in);
    if (layout && layout->radiance == RadianceFormat::kBc6h)
      return bc6hPageView(in, *layout, depth);
  }
  auto file = exrFileFor(in);
  if (!file) return file.status();
  return depth ? depthView(*file) : readExr(*file, kRgbChannels);
}

// The noise map for `in`: IN itself when it has channel E, else the noise page beside an
// atlas page (atlas.exr -> noise.exr, atlas.page2.exr -> noise.page2.exr).
Expected<std::string> noiseFileFor(const std::string& in) {
  fs::path path(in);
  if (fs::is_directory(path)) path /= "atlas.exr";
  const std::string name = path.filename().string();
  if (name.rfind("noise", 0) == 0) return path.string();
  if (name.rfind("atlas", 0) == 0) {
    fs::path noise = path.parent_path() / ("noise" + name.substr(5));
    if (fs::exists(noise)) return noise.string();
    return Status::error(in + ": no noise map beside it (" + noise.string() +
                         " is missing). rdm bake writes noise.exr, the per-texel relative "
                         "standard error; atlases fetched from the daemon and renders carry none");
  }
  return Status::error(in +
                       ": --noise needs an atlas directory, atlas.exr or noise.exr written by "
                       "rdm bake (single RDMs and renders carry no standard errors)");
}

// Relative standard error through the magma map, 0 to `full_scale` (clamped), with a legend.
Expected<Image8> noiseView(const std::string& in, double full_scale) {
  auto file = noiseFileFor(in);
  if (!file) return file.status();
  auto noise = readExr(*file, {kNoiseChannel});
  if (!noise) return noise.status();
  for (float& v : noise->pixels) v = std::isfinite(v) ? float(v / full_scale) : 1.0f;
  return appendColorLegend(magmaColorMap(*noise));
}

}  // namespace

int cmdPreview(const Args& args) {
  std::string in, out;
  double exposure = 0.0, noise_scale = 1.0;
  bool depth = false, noise = false;
  VerbApp app("preview",
              "PNG view of an EXR: tone-mapped colour (Reinhard + sRGB), the depth "
              "channel Z, or the bake's noise map.");
  app.add_option("IN", in,
                 "atlas.exr, atlas directory (a bc6h one: page 0 decoded), single RDM or "
                 "render (.exr)")
      ->required();
  app.add_option("-o,--output", out, "output PNG")->required();
  app.add_option("--exposure", exposure, "exposure in stops before tone mapping")
      ->check(anyNumber());
  auto* depth_flag = app.add_flag("--depth", depth, "show channel Z (distance) as z / (1 + z)");
  app.add_flag("--noise", noise,
               "show each texel's relative standard error (magma, legend 0..--noise-scale); "
               "needs noise.exr from rdm bake")
      ->excludes(depth_flag);
  app.add_option("--noise-scale", noise_scale,
                 "relative error shown as full scale by --noise (the legend's 1)")
      ->check(positiveNumber());
  if (auto code = parseArgs(app, args)) return *code;
  if (Status s = checkOutputFile(out); !s) return fail("preview", s.message());
  Status written;
  if (noise) {
    auto view = noiseView(in, noise_scale);
    if (!view) return fail("preview", view.error());
    written = writePng(out, view->width, view->height, view->channels, view->pixels);
  } else {
    auto image = previewImage(in, depth);
    if (!image) return fail("preview", image.error());
    if (!depth) {
      const float scale = float(std::exp2(exposure));
      for (float& v : image->pixels) v *= scale;
    }
    Image mapped = depth ? *image : tonemapReinhardSrgb(*image);
    written = writePng(out, mapped.width, mapped.height, 3, toBytes(mapped));
  }
  if (!written) return fail("preview", written.message());
  return 0;
}

}  // namespace rdm::cli
