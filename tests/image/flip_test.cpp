#include "rdm/image/flip.h"
#include "rdm/image/tonemap.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfOutputFile.h>
#include <gtest/gtest.h>
#include <stb_image.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "rdm/image/png_io.h"

namespace rdm {
namespace {

namespace fs = std::filesystem;

Image uniform(int w, int h, std::array<float, 3> rgb) {
  Image image(w, h, 3);
  for (size_t i = 0; i < image.pixels.size(); ++i) image.pixels[i] = rgb[i % 3];
  return image;
}

// Deterministic smooth-plus-noise pattern with values in [0, 1].
Image pattern(int w, int h, unsigned seed) {
  Image image(w, h, 3);
  uint32_t state = seed * 2654435761u + 1;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      for (int c = 0; c < 3; ++c) {
        state = state * 1664525u + 1013904223u;
        float noise = float(state >> 8) / float(1 << 24);
        image.at(x, y, c) =
            0.5f + 0.3f * std::sin(0.2f * x + c) * std::cos(0.15f * y) + 0.2f * (noise - 0.5f);
      }
    }
  }
  return image;
}

double ldrMean(const Image& a, const Image& b) {
  return computeLdrFlip(a, b).mean;
}

TEST(Flip, IdenticalImagesGiveExactlyZero) {
  Image image = pattern(64, 48, 1);
  FlipResult result = computeLdrFlip(image, image);
  ASSERT_EQ(result.error_map.width, 64);
  ASSERT_EQ(result.error_map.height, 48);
  ASSERT_EQ(result.error_map.channels, 1);
  for (float v : result.error_map.pixels) ASSERT_EQ(v, 0.0f);
  EXPECT_EQ(result.mean, 0.0);
}

TEST(Flip, ErrorGrowsAsGreyLevelDeparts) {
  Image reference = uniform(32, 32, {0.5f, 0.5f, 0.5f});
  for (float direction : {1.0f, -1.0f}) {
    double previous = 0.0;
    for (float d : {0.01f, 0.03f, 0.08f, 0.15f, 0.25f, 0.35f, 0.45f}) {
      float g = 0.5f + direction * d;
      double mean = ldrMean(reference, uniform(32, 32, {g, g, g}));
      EXPECT_GT(mean, previous) << "grey " << g;
      previous = mean;
    }
  }
}

TEST(Flip, MeanAndPixelsInUnitRange) {
  std::vector<std::pair<Image, Image>> pairs;
  pairs.emplace_back(pattern(48, 40, 2), pattern(48, 40, 3));
  pairs.emplace_back(uniform(48, 40, {0, 1, 0}), uniform(48, 40, {0, 0, 1}));
  pairs.emplace_back(uniform(48, 40, {1, 0, 1}), pattern(48, 40, 4));
  // Out-of-range and NaN inputs are clamped.
  pairs.emplace_back(uniform(48, 40, {-3, 7, NAN}), pattern(48, 40, 5));
  for (const auto& [a, b] : pairs) {
    FlipResult result = computeLdrFlip(a, b);
    EXPECT_GE(result.mean, 0.0);
    EXPECT_LE(result.mean, 1.0);
    for (float v : result.error_map.pixels) {
      ASSERT_GE(v, 0.0f);
      ASSERT_LE(v, 1.0f);
    }
  }
}

TEST(Flip, UniformColourPairsAreSymmetric) {
  const std::array<float, 3> colours[] = {{1, 0, 0},         {0, 1, 0}, {0, 0, 1},
                                          {1, 1, 0},         {0, 1, 1}, {0.2f, 0.4f, 0.9f},
                                          {0.5f, 0.5f, 0.5f}};
  for (const auto& a : colours) {
    for (const auto& b : colours) {
      Image ia = uniform(24, 24, a), ib = uniform(24, 24, b);
      EXPECT_NEAR(ldrMean(ia, ib), ldrMean(ib, ia), 1e-6);
    }
  }
}

TEST(Flip, BlackVersusWhiteIsNearOne) {
  // Uniform images have no feature difference, so FLIP is the redistributed HyAB colour
  // error of black vs white: ~0.967 (HyAB 100 sits above p_c c_max, just below c_max).
  Image black = uniform(32, 32, {0, 0, 0}), white = uniform(32, 32, {1, 1, 1});
  double mean = ldrMean(black, white);
  EXPECT_NEAR(mean, 1.0, 0.05);
  EXPECT_NEAR(ldrMean(white, black), mean, 1e-6);
}

TEST(Flip, EdgeInOneImageRaisesErrorAtTheEdge) {
  // The test has a faint vertical step (0.48 | 0.52) where the reference is flat 0.5. The
  // CSF-filtered colour difference is largest far from the step, so extra error near the
  // step comes from the feature term. Far away (beyond both filter radii, ~10 px at the
  // default ppd) the error equals that of the uniform pair, which has no feature term.
  const int w = 64, h = 16, edge = 32;
  Image reference = uniform(w, h, {0.5f, 0.5f, 0.5f}), test(w, h, 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) test.at(x, y, c) = x < edge ? 0.48f : 0.52f;
  FlipResult result = computeLdrFlip(reference, test);
  float near_left = 0.0f, near_right = 0.0f;
  for (int x = edge - 4; x < edge; ++x)
    near_left = std::max(near_left, result.error_map.at(x, h / 2, 0));
  for (int x = edge; x < edge + 4; ++x)
    near_right = std::max(near_right, result.error_map.at(x, h / 2, 0));
  float far_left = result.error_map.at(2, h / 2, 0),
        far_right = result.error_map.at(w - 3, h / 2, 0);
  EXPECT_NEAR(far_left, ldrMean(reference, uniform(w, h, {0.48f, 0.48f, 0.48f})), 1e-6);
  EXPECT_NEAR(far_right, ldrMean(reference, uniform(w, h, {0.52f, 0.52f, 0.52f})), 1e-6);
  EXPECT_GT(near_left, 1.2f * far_left);
  EXPECT_GT(near_right, 1.2f * far_right);
}

TEST(Flip, HdrFlipOfIdenticalImagesIsZero) {
  Image image = pattern(40, 32, 6);
  for (size_t i = 0; i < image.pixels.size(); ++i)
    image.pixels[i] = std::exp2(12.0f * image.pixels[i] - 6.0f);
  FlipResult result = computeHdrFlip(image, image);
  for (float v : result.error_map.pixels) ASSERT_EQ(v, 0.0f);
  EXPECT_EQ(result.mean, 0.0);
}

TEST(Flip, HdrFlipSeesDifferencesInBrightRegions) {
  // 50 vs 60 look almost the same after Reinhard (0.980 vs 0.984) but differ clearly at the
  // short exposures HDR-FLIP includes.
  const int n = 64;
  Image reference = uniform(n, n, {0.1f, 0.1f, 0.1f}), test = reference;
  for (int y = 24; y < 40; ++y)
    for (int x = 24; x < 40; ++x)
      for (int c = 0; c < 3; ++c) {
        reference.at(x, y, c) = 50.0f;
        test.at(x, y, c) = 60.0f;
      }
  FlipResult hdr = computeHdrFlip(reference, test);
  FlipResult ldr = computeLdrFlip(tonemapReinhardSrgb(reference), tonemapReinhardSrgb(test));
  EXPECT_GT(hdr.mean, 0.0);
  EXPECT_LE(hdr.mean, 1.0);
  EXPECT_GT(hdr.error_map.at(32, 32, 0), 0.05f);
  EXPECT_GT(hdr.error_map.at(32, 32, 0), 3.0f * ldr.error_map.at(32, 32, 0));
  EXPECT_EQ(hdr.error_map.at(0, 0, 0), 0.0f);  // farther than the filter radii from the square
}

TEST(Flip, SrgbCurveAndReinhard) {
  EXPECT_FLOAT_EQ(srgbEncode(0.0f), 0.0f);
  EXPECT_FLOAT_EQ(srgbEncode(1.0f), 1.0f);
  EXPECT_NEAR(srgbEncode(0.5f), 0.735357f, 1e-5);
  for (float v : {0.0f, 0.001f, 0.02f, 0.2f, 0.5f, 0.9f, 1.0f})
    EXPECT_NEAR(srgbDecode(srgbEncode(v)), v, 1e-6);
  Image linear(3, 1, 1);
  linear.pixels = {1.0f, -2.0f, INFINITY};
  Image mapped = tonemapReinhardSrgb(linear);
  EXPECT_NEAR(mapped.pixels[0], srgbEncode(0.5f), 1e-7);
  EXPECT_EQ(mapped.pixels[1], 0.0f);
  EXPECT_EQ(mapped.pixels[2], 1.0f);
}

TEST(Flip, MagmaMapAndLegend) {
  Image error(2, 1, 1);
  error.pixels = {0.0f, 1.0f};
  Image8 map = magmaColorMap(error);
  ASSERT_EQ(map.channels, 3);
  EXPECT_EQ(std::vector<uint8_t>(map.pixels.begin(), map.pixels.begin() + 3),
            (std::vector<uint8_t>{0, 0, 4}));
  EXPECT_EQ(std::vector<uint8_t>(map.pixels.begin() + 3, map.pixels.end()),
            (std::vector<uint8_t>{252, 253, 191}));
  Image wide(256, 20, 1);
  Image8 with_legend = appendColorLegend(magmaColorMap(wide));
  EXPECT_EQ(with_legend.width, 256);
  EXPECT_GT(with_legend.height, 20);
  EXPECT_EQ(with_legend.pixels.size(), size_t(with_legend.width) * with_legend.height * 3);
  EXPECT_EQ(with_legend.pixels[0], 0);  // the map itself is kept on top
}

uint32_t readU32(const std::vector<uint8_t>& bytes, size_t at) {
  return uint32_t(bytes[at]) << 24 | uint32_t(bytes[at + 1]) << 16 | uint32_t(bytes[at + 2]) << 8 |
         bytes[at + 3];
}

fs::path scratchDir(const std::string& name) {
  fs::path dir =
      fs::path(testing::TempDir()) / ("rdm_flip_test_" + name + "_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// The file is a PNG of the given size and colour type that a decoder (stb_image) reads back
// to the same bytes; no temporary file stays behind.
TEST(PngWriter, WritesAPngThatDecodesToThePixels) {
  fs::path dir = scratchDir("png");
  for (int channels : {3, 4}) {
    const int w = 7, h = 5;
    std::vector<uint8_t> pixels(size_t(w) * h * channels);
    for (size_t i = 0; i < pixels.size(); ++i) pixels[i] = uint8_t(i * 7);
    fs::path path = dir / ("out" + std::to_string(channels) + ".png");
    Status status = writePng(path.string(), w, h, channels, pixels);
    ASSERT_TRUE(status.ok()) << status.message();
    std::ifstream in(path, std::ios::binary);
    std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)),
                               std::istreambuf_iterator<char>());
    ASSERT_GT(bytes.size(), 33u + 12u);
    const uint8_t signature[] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    EXPECT_TRUE(std::equal(std::begin(signature), std::end(signature), bytes.begin()));
    EXPECT_EQ(std::string(bytes.begin() + 12, bytes.begin() + 16), "IHDR");
    EXPECT_EQ(readU32(bytes, 16), uint32_t(w));
    EXPECT_EQ(readU32(bytes, 20), uint32_t(h));
    EXPECT_EQ(bytes[24], 8);                      // bit depth
    EXPECT_EQ(bytes[25], channels == 4 ? 6 : 2);  // colour type
    int dw = 0, dh = 0, dc = 0;
    uint8_t* decoded = stbi_load_from_memory(bytes.data(), int(bytes.size()), &dw, &dh, &dc, 0);
    ASSERT_NE(decoded, nullptr) << stbi_failure_reason();
    EXPECT_EQ(dw, w);
    EXPECT_EQ(dh, h);
    EXPECT_EQ(dc, channels);
    EXPECT_TRUE(std::equal(pixels.begin(), pixels.end(), decoded));
    stbi_image_free(decoded);
  }
  size_t files = std::distance(fs::directory_iterator(dir), fs::directory_iterator());
  EXPECT_EQ(files, 2u);  // no temporary files left behind
  fs::remove_all(dir);
}

TEST(PngWriter, ReportsUnwritablePath) {
  std::string path = "/nonexistent-rdm-dir/x.png";
  Status status = writePng(path, 1, 1, 3, {1, 2, 3});
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("/nonexistent-rdm-dir/x.png"), std::string::npos);
}

void writeExr(const fs::path& path, const Image& image, const char* channels = "RGB") {
  Imf::Header header(image.width, image.height);
  Imf::FrameBuffer frame;
  for (int c = 0; channels[c]; ++c) {
    std::string name(1, channels[c]);
    header.channels().insert(name, Imf::Channel(Imf::FLOAT));
    frame.insert(name, Imf::Slice(Imf::FLOAT, (char*)(image.pixels.data() + c), 3 * sizeof(float),
                                  3 * sizeof(float) * image.width));
  }
  Imf::OutputFile file(path.c_str(), header);
  file.setFrameBuffer(frame);
  file.writePixels(image.height);
}

struct CliResult {
  int code;
  std::string out, err;
};

CliResult runFlip(const fs::path& dir, const std::string& args) {
  fs::path out = dir / "stdout.txt", err = dir / "stderr.txt";
  std::string command =
      std::string(RDM_BINARY) + " flip " + args + " >" + out.string() + " 2>" + err.string();
  int status = std::system(command.c_str());
  auto slurp = [](const fs::path& p) {
    std::ifstream in(p);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  };
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(out), slurp(err)};
}

TEST(FlipCli, ReportsMeansAndChecksInputs) {
  fs::path dir = scratchDir("cli");
  Image a = pattern(40, 30, 7), b = pattern(40, 30, 8);
  writeExr(dir / "a.exr", a);
  writeExr(dir / "b.exr", b);
  writeExr(dir / "small.exr", pattern(20, 30, 9));
  writeExr(dir / "rg.exr", a, "RG");
  std::string pa = (dir / "a.exr").string(), pb = (dir / "b.exr").string();

  CliResult same = runFlip(dir, pa + " " + pa);
  EXPECT_EQ(same.code, 0) << same.err;
  EXPECT_EQ(same.out, "mean LDR-FLIP: 0.000000\n");

  CliResult diff =
      runFlip(dir, pa + " " + pb + " --hdr --ppd 30 --map " + (dir / "m.png").string());
  EXPECT_EQ(diff.code, 0) << diff.err;
  char expected[64];
  std::snprintf(expected, sizeof expected, "mean LDR-FLIP: %.6f\n",
                computeLdrFlip(tonemapReinhardSrgb(a), tonemapReinhardSrgb(b), 30).mean);
  EXPECT_EQ(diff.out.substr(0, diff.out.find('\n') + 1), expected);
  EXPECT_NE(diff.out.find("mean HDR-FLIP: "), std::string::npos);
  EXPECT_TRUE(fs::exists(dir / "m.png"));

  CliResult mismatch = runFlip(dir, pa + " " + (dir / "small.exr").string());
  EXPECT_EQ(mismatch.code, 1);
  EXPECT_NE(mismatch.err.find("small.exr"), std::string::npos) << mismatch.err;
  CliResult missing = runFlip(dir, pa + " " + (dir / "none.exr").string());
  EXPECT_EQ(missing.code, 1);
  EXPECT_NE(missing.err.find("none.exr"), std::string::npos) << missing.err;
  CliResult no_blue = runFlip(dir, (dir / "rg.exr").string() + " " + pa);
  EXPECT_EQ(no_blue.code, 1);
  EXPECT_NE(no_blue.err.find("no channel 'B'"), std::string::npos) << no_blue.err;
  EXPECT_EQ(runFlip(dir, pa).code, 2);
  EXPECT_EQ(runFlip(dir, pa + " " + pb + " --ppd -1").code, 2);
  EXPECT_EQ(runFlip(dir, pa + " " + pb + " --bogus").code, 2);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rdm
