// Measures the BC6H encoder on a baked atlas (docs/bc6h.md): speed, error per mode set, and the
// bytes of each container. Skipped unless RDM_BC6H_ATLAS names an atlas directory, e.g.
//   rdm bake --scene chess -o /tmp/bc6h_chess
//   RDM_BC6H_ATLAS=/tmp/bc6h_chess rdm_tests --gtest_filter='Bc6hMeasure*'
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <string>

#include "rdm/base/parallel.h"
#include "rdm/image/bc6h.h"
#include "rdm/image/exr_io.h"
#include "rdm/image/ktx2.h"

namespace rdm {
namespace {

namespace fs = std::filesystem;

struct Errors {
  double rmse = 0;           // over every R, G, B value, in radiance units
  double mean_relative = 0;  // mean |decoded - source| / source over values with source > 0
  double p99_relative = 0;
};

Errors measure(const Image& source, const Image& decoded) {
  double squared = 0, relative = 0;
  std::vector<float> relatives;
  for (int y = 0; y < source.height; ++y)
    for (int x = 0; x < source.width; ++x)
      for (int c = 0; c < 3; ++c) {
        const double s = bc6hClampInput(source.at(x, y, c)), d = decoded.at(x, y, c);
        squared += (d - s) * (d - s);
        if (s > 0) relatives.push_back(float(std::abs(d - s) / s)), relative += relatives.back();
      }
  Errors errors;
  errors.rmse = std::sqrt(squared / (3.0 * source.width * source.height));
  errors.mean_relative = relatives.empty() ? 0 : relative / double(relatives.size());
  if (!relatives.empty()) {
    const size_t at = relatives.size() * 99 / 100;
    std::nth_element(relatives.begin(), relatives.begin() + long(at), relatives.end());
    errors.p99_relative = relatives[at];
  }
  return errors;
}

std::map<int, int> modeCounts(const Bc6hImage& image) {
  std::map<int, int> counts;
  for (size_t at = 0; at < image.blocks.size(); at += kBc6hBlockBytes) {
    Bc6hBlock block;
    std::copy_n(image.blocks.begin() + long(at), kBc6hBlockBytes, block.begin());
    ++counts[bc6hBlockMode(block)];
  }
  return counts;
}

uintmax_t exrBytes(const Image& image, const std::vector<std::string>& channels,
                   const std::vector<std::string>& half_channels) {
  const std::string path =
      (fs::temp_directory_path() / ("rdm_bc6h_measure_" + std::to_string(::getpid()) + ".exr"))
          .string();
  EXPECT_TRUE(writeExr(path, image, channels, half_channels).ok());
  const uintmax_t bytes = fs::file_size(path);
  fs::remove(path);
  return bytes;
}

TEST(Bc6hMeasure, AtlasPage) {
  const char* dir = std::getenv("RDM_BC6H_ATLAS");
  if (dir == nullptr) GTEST_SKIP() << "RDM_BC6H_ATLAS names no atlas directory";
  const std::string page = std::string(dir) + "/atlas.exr";
  Expected<Image> rgb = readExr(page, kRgbChannels);
  ASSERT_TRUE(rgb.ok()) << rgb.error();
  const double texels = double(rgb->width) * rgb->height;
  double sum = 0, peak = 0;
  for (float v : rgb->pixels) sum += v, peak = std::max(peak, double(v));
  std::printf("page %s: %d x %d, mean R G B value %.4g, largest %.4g\n", page.c_str(), rgb->width,
              rgb->height, sum / double(rgb->pixels.size()), peak);
  const char* names[] = {"mode 11", "modes 11-14", "all modes"};
  for (Bc6hModeSet modes : {Bc6hModeSet::kMode11, Bc6hModeSet::kOneRegion, Bc6hModeSet::kAll}) {
    const uint64_t start = threadCpuNanoseconds();
    Expected<Bc6hImage> encoded = encodeBc6h(*rgb, {modes, 1});
    const double seconds = double(threadCpuNanoseconds() - start) * 1e-9;
    ASSERT_TRUE(encoded.ok()) << encoded.error();
    Expected<Image> decoded = decodeBc6h(*encoded);
    ASSERT_TRUE(decoded.ok());
    const Errors e = measure(*rgb, *decoded);
    std::printf(
        "%-12s %.3f CPU s, %.2f Mtexels/CPU-s, RMSE %.5g, mean rel %.4f%%, p99 rel %.3f%%\n",
        names[int(modes)], seconds, texels / seconds * 1e-6, e.rmse, 100 * e.mean_relative,
        100 * e.p99_relative);
    std::printf("  blocks per mode:");
    for (const auto& [mode, count] : modeCounts(*encoded)) std::printf(" %d: %d", mode, count);
    std::printf("\n");
    if (modes == Bc6hModeSet::kAll) {
      const Ktx2Image ktx{Ktx2Format::kBc6hUfloat, encoded->width, encoded->height,
                          encoded->blocks};
      Expected<Image> depth = readExr(page, {"Z"});
      ASSERT_TRUE(depth.ok()) << depth.error();
      std::printf(
          "bytes: atlas.exr (RGBZ float32) %ju, RGB float32 EXR %ju, RGB half EXR %ju, "
          "BC6H KTX2 %zu, Z float32 EXR %ju\n",
          fs::file_size(page), exrBytes(*rgb, kRgbChannels, {}),
          exrBytes(*rgb, kRgbChannels, kRgbChannels), encodeKtx2(ktx).size(),
          exrBytes(*depth, {"Z"}, {}));
    }
  }
}

}  // namespace
}  // namespace rdm
