#include "rdm/image/exr_io.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfMultiPartInputFile.h>
#include <OpenEXR/ImfOutputFile.h>

#include <array>
#include <bit>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <vector>

namespace rdm {
namespace {

namespace fs = std::filesystem;

class ExrIoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("rdm_exr_io_test_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string file(const std::string& name) const { return (dir_ / name).string(); }

  fs::path dir_;
};

// Values that survive only a bit-exact FLOAT path: above half's range, signed zero,
// denormals, infinities, a NaN payload.
std::vector<float> specialValues() {
  return {0.0f,
          -0.0f,
          1.0f,
          65504.0f,
          65505.0f,
          1.0e6f,
          -3.5e7f,
          std::numeric_limits<float>::max(),
          std::numeric_limits<float>::denorm_min(),
          -std::numeric_limits<float>::denorm_min(),
          std::numeric_limits<float>::min() / 3.0f,
          std::numeric_limits<float>::infinity(),
          -std::numeric_limits<float>::infinity(),
          std::bit_cast<float>(uint32_t(0x7fc01234u)),
          0.1f,
          1.0e-30f};
}

// Distinct per pixel and channel, with the special values spread over the image; spans
// several 16-scanline ZIP blocks.
Image testImage(int width, int height, int channels) {
  Image image(width, height, channels);
  const std::vector<float> special = specialValues();
  for (size_t i = 0; i < image.pixels.size(); ++i) {
    image.pixels[i] = i % 5 == 0 ? special[(i / 5) % special.size()] : float(i) * 1.25f + 7e4f;
  }
  return image;
}

void expectBitEqual(const Image& expected, const Image& actual) {
  ASSERT_EQ(expected.width, actual.width);
  ASSERT_EQ(expected.height, actual.height);
  ASSERT_EQ(expected.channels, actual.channels);
  ASSERT_EQ(expected.pixels.size(), actual.pixels.size());
  for (size_t i = 0; i < expected.pixels.size(); ++i) {
    ASSERT_EQ(std::bit_cast<uint32_t>(expected.pixels[i]),
              std::bit_cast<uint32_t>(actual.pixels[i]))
        << "float " << i << ": " << expected.pixels[i] << " vs " << actual.pixels[i];
  }
}

std::string fileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

TEST_F(ExrIoTest, RgbzRoundTripIsBitExact) {
  Image image = testImage(13, 37, 4);
  image.at(0, 0, 1) = -0.0f;
  image.at(12, 36, 3) = 1.0e9f;
  const std::string path = file("atlas.exr");
  ASSERT_TRUE(writeExr(path, image, kRgbzChannels).ok());
  Expected<Image> read = readExr(path, kRgbzChannels);
  ASSERT_TRUE(read.ok()) << read.error();
  expectBitEqual(image, *read);
  EXPECT_EQ(std::bit_cast<uint32_t>(read->at(0, 0, 1)), std::bit_cast<uint32_t>(-0.0f));
}

TEST_F(ExrIoTest, ChannelOrderFollowsNamesNotFileOrder) {
  const std::vector<std::string> names = {"Z", "R", "A", "G"};  // file stores A, G, R, Z
  const Image image = testImage(5, 4, 4);
  const std::string path = file("order.exr");
  ASSERT_TRUE(writeExr(path, image, names).ok());
  Expected<Image> same = readExr(path, names);
  ASSERT_TRUE(same.ok()) << same.error();
  expectBitEqual(image, *same);

  Expected<Image> subset = readExr(path, {"G", "Z"});
  ASSERT_TRUE(subset.ok()) << subset.error();
  ASSERT_EQ(subset->channels, 2);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      EXPECT_EQ(std::bit_cast<uint32_t>(subset->at(x, y, 0)),
                std::bit_cast<uint32_t>(image.at(x, y, 3)));
      EXPECT_EQ(std::bit_cast<uint32_t>(subset->at(x, y, 1)),
                std::bit_cast<uint32_t>(image.at(x, y, 0)));
    }
  }
}

TEST_F(ExrIoTest, MemoryEncodingEqualsFileBytesAndDecodes) {
  const Image image = testImage(9, 40, 4);
  const std::string path = file("mem.exr");
  ASSERT_TRUE(writeExr(path, image, kRgbzChannels).ok());
  Expected<std::string> bytes = encodeExr(image, kRgbzChannels);
  ASSERT_TRUE(bytes.ok()) << bytes.error();
  EXPECT_EQ(*bytes, fileBytes(path));

  Expected<Image> decoded = decodeExr(*bytes, kRgbzChannels);
  ASSERT_TRUE(decoded.ok()) << decoded.error();
  expectBitEqual(image, *decoded);
}

// Noise (incompressible: a file over FileOStream's 1 MiB runs) in 700 x 300 x 4 floats:
// 19 ZIP chunks of 16 rows.
Image noiseImage() {
  Image image(700, 300, 4);
  std::mt19937 rng(42);
  std::uniform_real_distribution<float> u(0.0f, 1e4f);
  for (float& p : image.pixels) p = u(rng);
  return image;
}

// The file OpenEXR writes itself, on the calling thread, with writeExr's header.
std::string plainOpenExrBytes(const std::string& path, const Image& image) {
  Imf::Header header(image.width, image.height);
  header.compression() = Imf::ZIP_COMPRESSION;
  header.lineOrder() = Imf::INCREASING_Y;
  Imf::FrameBuffer frame_buffer;
  const size_t x_stride = 4 * sizeof(float), y_stride = x_stride * size_t(image.width);
  for (size_t c = 0; c < kRgbzChannels.size(); ++c) {
    header.channels().insert(kRgbzChannels[c], Imf::Channel(Imf::FLOAT));
    char* base = reinterpret_cast<char*>(const_cast<float*>(image.pixels.data() + c));
    frame_buffer.insert(kRgbzChannels[c], Imf::Slice(Imf::FLOAT, base, x_stride, y_stride));
  }
  {
    Imf::OutputFile out(path.c_str(), header, 0);
    out.setFrameBuffer(frame_buffer);
    out.writePixels(image.height);
  }
  return fileBytes(path);
}

TEST_F(ExrIoTest, BytesDoNotDependOnCompressionThreads) {
  // Byte for byte: writeExr and encodeExr on 1, 2 and 5 threads, and OpenEXR's own
  // single-threaded file; FLOAT and HALF channels; read back on several threads too.
  const Image image = noiseImage();
  const std::string plain = plainOpenExrBytes(file("plain.exr"), image);
  ASSERT_GT(plain.size(), size_t(1) << 20);
  std::string half_bytes;
  for (int threads : {1, 2, 5}) {
    setExrThreads(threads);
    const std::string path = file("t" + std::to_string(threads) + ".exr");
    ASSERT_TRUE(writeExr(path, image, kRgbzChannels).ok());
    EXPECT_EQ(fileBytes(path), plain) << threads << " threads";
    Expected<std::string> bytes = encodeExr(image, kRgbzChannels);
    ASSERT_TRUE(bytes.ok()) << bytes.error();
    EXPECT_EQ(*bytes, plain) << threads << " threads";
    ASSERT_TRUE(writeExr(path, image, kRgbzChannels, {"R", "G", "B"}).ok());
    if (threads == 1) half_bytes = fileBytes(path);
    EXPECT_EQ(fileBytes(path), half_bytes) << threads << " threads, HALF";
    Expected<Image> read = readExr(file("plain.exr"), kRgbzChannels);
    ASSERT_TRUE(read.ok()) << read.error();
    expectBitEqual(image, *read);
  }
  setExrThreads(0);
}

TEST_F(ExrIoTest, HeaderFollowsSpecConventions) {
  const Image image = testImage(11, 21, 4);
  const std::string path = file("header.exr");
  ASSERT_TRUE(writeExr(path, image, kRgbzChannels).ok());

  EXPECT_EQ(Imf::MultiPartInputFile(path.c_str()).parts(), 1);
  Imf::InputFile file(path.c_str());
  const Imf::Header& header = file.header();
  EXPECT_EQ(header.compression(), Imf::ZIP_COMPRESSION);
  EXPECT_EQ(header.lineOrder(), Imf::INCREASING_Y);
  EXPECT_FALSE(header.hasTileDescription());
  EXPECT_EQ(header.dataWindow().min, Imath::V2i(0, 0));
  EXPECT_EQ(header.dataWindow().max, Imath::V2i(10, 20));
  EXPECT_EQ(header.displayWindow().min, Imath::V2i(0, 0));
  EXPECT_EQ(header.displayWindow().max, Imath::V2i(10, 20));

  std::set<std::string> channels;
  for (auto it = header.channels().begin(); it != header.channels().end(); ++it) {
    channels.insert(it.name());
    EXPECT_EQ(it.channel().type, Imf::FLOAT) << it.name();
  }
  EXPECT_EQ(channels, (std::set<std::string>{"B", "G", "R", "Z"}));

  std::set<std::string> attributes;
  for (auto it = header.begin(); it != header.end(); ++it) attributes.insert(it.name());
  EXPECT_EQ(attributes, (std::set<std::string>{"channels", "compression", "dataWindow",
                                               "displayWindow", "lineOrder", "pixelAspectRatio",
                                               "screenWindowCenter", "screenWindowWidth"}));

  // The file's first scanline is image row 0: nothing flips rows.
  std::vector<float> row(image.width);
  Imf::FrameBuffer frame_buffer;
  frame_buffer.insert(
      "Z", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(row.data()), sizeof(float), 0));
  file.setFrameBuffer(frame_buffer);
  file.readPixels(0, 0);
  for (int x = 0; x < image.width; ++x) {
    EXPECT_EQ(std::bit_cast<uint32_t>(row[x]), std::bit_cast<uint32_t>(image.at(x, 0, 3)));
  }
}

TEST_F(ExrIoTest, WriteLeavesNoTempFileAndReplacesExisting) {
  const std::string path = file("out.exr");
  ASSERT_TRUE(writeExr(path, testImage(3, 2, 3), kRgbChannels).ok());
  const Image second = testImage(4, 3, 3);
  ASSERT_TRUE(writeExr(path, second, kRgbChannels).ok());
  EXPECT_TRUE(fs::exists(path));
  EXPECT_FALSE(fs::exists(path + ".tmp"));
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 1);
  Expected<Image> read = readExr(path, kRgbChannels);
  ASSERT_TRUE(read.ok()) << read.error();
  expectBitEqual(second, *read);
}

TEST_F(ExrIoTest, WriteIntoMissingDirectoryFailsAndLeavesNothing) {
  const fs::path missing = dir_ / "no_such_dir";
  const std::string path = (missing / "out.exr").string();
  Status status = writeExr(path, testImage(3, 2, 3), kRgbChannels);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find(path), std::string::npos) << status.message();
  EXPECT_FALSE(fs::exists(missing));
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 0);
}

TEST_F(ExrIoTest, MissingChannelFailsNamingChannelAndFile) {
  const std::string path = file("rgb.exr");
  ASSERT_TRUE(writeExr(path, testImage(3, 2, 3), kRgbChannels).ok());
  Expected<Image> read = readExr(path, kRgbzChannels);
  ASSERT_FALSE(read.ok());
  EXPECT_NE(read.error().find("'Z'"), std::string::npos) << read.error();
  EXPECT_NE(read.error().find(path), std::string::npos) << read.error();

  Expected<Image> decoded = decodeExr(fileBytes(path), {"R", "depth"});
  ASSERT_FALSE(decoded.ok());
  EXPECT_NE(decoded.error().find("'depth'"), std::string::npos) << decoded.error();
}

// readFiniteExr names the first non-finite value's channel and pixel; finite images read as
// readExr reads them.
TEST_F(ExrIoTest, NonFiniteValueIsRefusedNamingChannelAndPixel) {
  Image image(5, 4, 3);
  for (size_t i = 0; i < image.pixels.size(); ++i) image.pixels[i] = 0.5f * float(i);
  const std::string finite = file("finite.exr"), nan = file("nan.exr");
  ASSERT_TRUE(writeExr(finite, image, kRgbChannels).ok());
  Expected<Image> read = readFiniteExr(finite, kRgbChannels);
  ASSERT_TRUE(read.ok()) << read.error();
  expectBitEqual(image, *read);
  image.at(3, 2, 1) = std::numeric_limits<float>::quiet_NaN();
  image.at(4, 3, 0) = std::numeric_limits<float>::infinity();
  ASSERT_TRUE(writeExr(nan, image, kRgbChannels).ok());
  read = readFiniteExr(nan, kRgbChannels);
  ASSERT_FALSE(read.ok());
  EXPECT_NE(read.error().find("channel G at pixel (3, 2)"), std::string::npos) << read.error();
  EXPECT_NE(read.error().find(nan), std::string::npos) << read.error();
}

TEST_F(ExrIoTest, NonExrInputFailsCleanly) {
  const std::string path = file("scene.json");
  std::ofstream(path) << "{\"format\": \"not an exr\"}\n";
  Expected<Image> read = readExr(path, kRgbChannels);
  ASSERT_FALSE(read.ok());
  EXPECT_NE(read.error().find(path), std::string::npos) << read.error();

  const std::string missing = file("missing.exr");
  Expected<Image> absent = readExr(missing, kRgbChannels);
  ASSERT_FALSE(absent.ok());
  EXPECT_NE(absent.error().find(missing), std::string::npos) << absent.error();

  EXPECT_FALSE(decodeExr("", kRgbChannels).ok());
  EXPECT_FALSE(decodeExr("not an exr at all", kRgbChannels).ok());
}

TEST_F(ExrIoTest, TruncatedDataFailsCleanly) {
  Expected<std::string> bytes = encodeExr(testImage(16, 48, 4), kRgbzChannels);
  ASSERT_TRUE(bytes.ok()) << bytes.error();
  for (size_t size : {size_t(4), size_t(40), bytes->size() / 2, bytes->size() - 1}) {
    Expected<Image> decoded = decodeExr(bytes->substr(0, size), kRgbzChannels);
    EXPECT_FALSE(decoded.ok()) << "truncated to " << size << " bytes";
  }
}

// Overwrites the four int32 of the dataWindow attribute (min.x, min.y, max.x, max.y).
std::string withDataWindow(std::string bytes, const std::array<int32_t, 4>& window) {
  const std::string key("dataWindow\0box2i\0", 17);
  const size_t at = bytes.find(key);
  RDM_CHECK(at != std::string::npos);
  std::memcpy(bytes.data() + at + key.size() + 4, window.data(), sizeof(window));  // little endian
  return bytes;
}

TEST_F(ExrIoTest, HostileDataWindowsFailBeforeAllocating) {
  // Big enough that OpenEXR finds a whole line offset table for the hostile window.
  Expected<std::string> bytes = encodeExr(testImage(64, 64, 3), kRgbChannels);
  ASSERT_TRUE(bytes.ok()) << bytes.error();
  ASSERT_GT(bytes->size(), 1025u * 8u);
  ASSERT_TRUE(decodeExr(withDataWindow(*bytes, {0, 0, 63, 63}), kRgbChannels).ok());

  Expected<Image> huge = decodeExr(withDataWindow(*bytes, {0, 0, 16383, 16384}), kRgbChannels);
  ASSERT_FALSE(huge.ok());
  EXPECT_NE(huge.error().find("image size"), std::string::npos) << huge.error();

  Expected<Image> shifted = decodeExr(withDataWindow(*bytes, {1, 1, 64, 64}), kRgbChannels);
  ASSERT_FALSE(shifted.ok());
  EXPECT_NE(shifted.error().find("data window"), std::string::npos) << shifted.error();
}

TEST_F(ExrIoTest, BadImagesAreErrorsNotCrashes) {
  const std::string path = file("bad.exr");
  Image empty;
  empty.channels = 3;
  EXPECT_FALSE(writeExr(path, empty, kRgbChannels).ok());
  EXPECT_FALSE(encodeExr(Image(0, 4, 3), kRgbChannels).ok());
  EXPECT_FALSE(encodeExr(Image(4, 0, 3), kRgbChannels).ok());
  EXPECT_FALSE(encodeExr(Image(2, 2, 3), kRgbzChannels).ok());  // channel count mismatch
  EXPECT_FALSE(encodeExr(Image(2, 2, 2), {"R", "R"}).ok());     // duplicate name
  EXPECT_FALSE(encodeExr(Image(2, 2, 2), {"R", ""}).ok());      // empty name
  Image huge;  // checked before its (absent) pixels are touched
  huge.width = 16385;
  huge.height = 16384;
  huge.channels = 3;
  EXPECT_FALSE(encodeExr(huge, kRgbChannels).ok());
  Image short_pixels(2, 2, 3);
  short_pixels.pixels.pop_back();
  EXPECT_FALSE(encodeExr(short_pixels, kRgbChannels).ok());
  EXPECT_FALSE(fs::exists(path));
  EXPECT_FALSE(fs::exists(path + ".tmp"));

  ASSERT_TRUE(writeExr(path, testImage(2, 2, 3), kRgbChannels).ok());
  EXPECT_FALSE(readExr(path, {}).ok());
  EXPECT_FALSE(readExr(path, {"R", "R"}).ok());
}

}  // namespace
}  // namespace rdm
