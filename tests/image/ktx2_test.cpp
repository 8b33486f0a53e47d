#include "rdm/image/ktx2.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <string>

#include "rdm/base/file_util.h"

namespace rdm {
namespace {

namespace fs = std::filesystem;

uint32_t field32(const std::string& bytes, size_t at) {
  uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= uint32_t(uint8_t(bytes[at + i])) << (8 * i);
  return v;
}

uint64_t field64(const std::string& bytes, size_t at) {
  return uint64_t(field32(bytes, at)) | (uint64_t(field32(bytes, at + 4)) << 32);
}

void setField32(std::string& bytes, size_t at, uint32_t v) {
  for (int i = 0; i < 4; ++i) bytes[at + i] = char((v >> (8 * i)) & 0xFF);
}

Ktx2Image sampleImage(Ktx2Format format, int width, int height) {
  Ktx2Image image;
  image.format = format;
  image.width = width;
  image.height = height;
  image.data.resize(ktx2LevelBytes(format, width, height));
  for (size_t i = 0; i < image.data.size(); ++i) image.data[i] = uint8_t(i * 37 + 11);
  return image;
}

class Ktx2Test : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("rdm_ktx2_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string file(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

// The refusal of `bytes`, which must name `field`.
void expectRefused(const std::string& bytes, const std::string& field) {
  Expected<Ktx2Image> image = decodeKtx2(bytes);
  ASSERT_FALSE(image.ok()) << field;
  EXPECT_EQ(image.status().field(), field) << image.error();
  EXPECT_NE(image.error().find(field), std::string::npos) << image.error();
}

TEST_F(Ktx2Test, Bc6hRoundTripsThroughAFile) {
  const Ktx2Image image = sampleImage(Ktx2Format::kBc6hUfloat, 832, 1088);
  ASSERT_TRUE(writeKtx2(file("atlas.ktx2"), image).ok());
  Expected<Ktx2Image> read = readKtx2(file("atlas.ktx2"));
  ASSERT_TRUE(read.ok()) << read.error();
  EXPECT_EQ(read->format, Ktx2Format::kBc6hUfloat);
  EXPECT_EQ(read->width, 832);
  EXPECT_EQ(read->height, 1088);
  EXPECT_EQ(read->data, image.data);
  for (const auto& entry : fs::directory_iterator(dir_))
    EXPECT_EQ(entry.path().filename(), "atlas.ktx2");  // no temporary file left behind
}

TEST_F(Ktx2Test, Bc6hHeaderAndDescriptorFields) {
  const std::string bytes = encodeKtx2(sampleImage(Ktx2Format::kBc6hUfloat, 8, 4));
  EXPECT_EQ(bytes.substr(0, 12), std::string("\xABKTX 20\xBB\r\n\x1A\n", 12));
  EXPECT_EQ(field32(bytes, 12), 143u);  // VK_FORMAT_BC6H_UFLOAT_BLOCK
  EXPECT_EQ(field32(bytes, 16), 1u);    // typeSize of block-compressed formats
  EXPECT_EQ(field32(bytes, 20), 8u);
  EXPECT_EQ(field32(bytes, 24), 4u);
  EXPECT_EQ(field32(bytes, 28), 0u);  // pixelDepth
  EXPECT_EQ(field32(bytes, 32), 0u);  // layerCount
  EXPECT_EQ(field32(bytes, 36), 1u);  // faceCount
  EXPECT_EQ(field32(bytes, 40), 1u);  // levelCount
  EXPECT_EQ(field32(bytes, 44), 0u);  // supercompressionScheme
  const uint32_t dfd = field32(bytes, 48);
  EXPECT_EQ(dfd, 104u);
  EXPECT_EQ(field32(bytes, 52), 44u);                    // dfdTotalSize + 24-byte block + 1 sample
  EXPECT_EQ(field32(bytes, dfd), 44u);                   // dfdTotalSize
  EXPECT_EQ(field32(bytes, dfd + 4), 0u);                // Khronos vendor, basic descriptor
  EXPECT_EQ(field32(bytes, dfd + 8), 2u | (40u << 16));  // version 2, 40-byte block
  EXPECT_EQ(field32(bytes, dfd + 12), 133u | (1u << 8) | (1u << 16));  // BC6H, BT.709, linear
  EXPECT_EQ(field32(bytes, dfd + 16), 3u | (3u << 8));                 // 4 x 4 texel block
  EXPECT_EQ(field32(bytes, dfd + 20), 16u);                            // bytesPlane0
  EXPECT_EQ(field32(bytes, dfd + 28), 127u << 16 | 0x80u << 24);       // 128 bits, float
  const uint64_t offset = field64(bytes, 80);
  EXPECT_EQ(offset % 16, 0u);
  EXPECT_EQ(field64(bytes, 88), 2u * 16u);  // two blocks
  EXPECT_EQ(field64(bytes, 96), 2u * 16u);
  EXPECT_EQ(bytes.size(), offset + 32);
}

TEST_F(Ktx2Test, Rgba16RoundTripsWithFourSamples) {
  const Ktx2Image image = sampleImage(Ktx2Format::kRgba16Sfloat, 5, 3);
  const std::string bytes = encodeKtx2(image);
  EXPECT_EQ(field32(bytes, 12), 97u);
  EXPECT_EQ(field32(bytes, 16), 2u);
  EXPECT_EQ(field32(bytes, 52), 92u);  // 4 + 24 + 4 samples of 16
  EXPECT_EQ(field64(bytes, 88), 5u * 3u * 8u);
  EXPECT_EQ(field64(bytes, 80) % 8, 0u);
  Expected<Ktx2Image> read = decodeKtx2(bytes);
  ASSERT_TRUE(read.ok()) << read.error();
  EXPECT_EQ(read->format, Ktx2Format::kRgba16Sfloat);
  EXPECT_EQ(read->data, image.data);
}

TEST_F(Ktx2Test, EveryTruncationIsRefused) {
  const std::string bytes = encodeKtx2(sampleImage(Ktx2Format::kBc6hUfloat, 8, 8));
  for (size_t size = 0; size < bytes.size(); ++size) {
    Expected<Ktx2Image> image = decodeKtx2(bytes.substr(0, size));
    ASSERT_FALSE(image.ok()) << size;
    EXPECT_EQ(image.status().code(), StatusCode::kCorrupt) << size << ": " << image.error();
  }
  expectRefused(bytes.substr(0, 40), "header");
  expectRefused(bytes.substr(0, 100), "levelIndex");
  expectRefused(bytes.substr(0, bytes.size() - 1), "levels[0].byteOffset");
}

TEST_F(Ktx2Test, CorruptFieldsAreNamed) {
  const std::string good = encodeKtx2(sampleImage(Ktx2Format::kBc6hUfloat, 8, 8));
  ASSERT_TRUE(decodeKtx2(good).ok());
  struct Case {
    size_t at;
    uint32_t value;
    const char* field;
  };
  const uint32_t dfd = field32(good, 48);
  const Case cases[] = {
      {0, 0x58544B00, "identifier"},
      {12, 98, "vkFormat"},
      {16, 4, "typeSize"},
      {20, 0, "pixelWidth"},
      {24, 20000, "pixelHeight"},
      {28, 1, "pixelDepth"},
      {32, 2, "layerCount"},
      {36, 6, "faceCount"},
      {40, 3, "levelCount"},
      {44, 2, "supercompressionScheme"},
      {52, 1u << 30, "dfdByteOffset"},
      {60, 1u << 30, "kvdByteOffset"},
      {72, 5, "sgdByteLength"},
      {80, field32(good, 80) + 4, "levels[0].byteOffset"},
      {88, 48, "levels[0].byteLength"},
      {96, 7, "levels[0].uncompressedByteLength"},
      {dfd, 40, "dfdTotalSize"},
      {dfd + 12, 1 | (1 << 8) | (1 << 16), "dfd.colorModel"},
      {dfd + 20, 8, "dfd.bytesPlane0"},
  };
  for (const Case& c : cases) {
    std::string bytes = good;
    setField32(bytes, c.at, c.value);
    expectRefused(bytes, c.field);
  }
}

TEST_F(Ktx2Test, ReadErrorsNameThePath) {
  Expected<Ktx2Image> missing = readKtx2(file("missing.ktx2"));
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().find("missing.ktx2"), std::string::npos);
  ASSERT_TRUE(writeFileAtomic(file("short.ktx2"), "\xABKTX 20").ok());
  Expected<Ktx2Image> cut = readKtx2(file("short.ktx2"));
  ASSERT_FALSE(cut.ok());
  EXPECT_EQ(cut.status().field(), "header");
  EXPECT_NE(cut.error().find("short.ktx2"), std::string::npos);
}

}  // namespace
}  // namespace rdm
