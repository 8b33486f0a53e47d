// RFC 4648 base64 (standard alphabet, padded, no line breaks) as used by the scene file's
// voxel payloads (docs/spec.md section 2).
#include "rdm/base/base64.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <string>
#include <utility>
#include <vector>

namespace rdm {
namespace {

std::vector<uint8_t> bytesOf(const std::string& s) {
  return std::vector<uint8_t>(s.begin(), s.end());
}

// Decoding must fail and the message must contain `needle`.
void expectRefused(const std::string& text, const std::string& needle) {
  SCOPED_TRACE("input '" + text + "'");
  auto decoded = base64Decode(text);
  ASSERT_FALSE(decoded.ok());
  EXPECT_NE(decoded.error().find(needle), std::string::npos) << decoded.error();
}

TEST(Base64Test, Rfc4648Vectors) {
  const std::vector<std::pair<std::string, std::string>> vectors = {
      {"", ""},
      {"f", "Zg=="},
      {"fo", "Zm8="},
      {"foo", "Zm9v"},
      {"foob", "Zm9vYg=="},
      {"fooba", "Zm9vYmE="},
      {"foobar", "Zm9vYmFy"},
  };
  for (const auto& [plain, encoded] : vectors) {
    SCOPED_TRACE(plain);
    EXPECT_EQ(base64Encode(bytesOf(plain)), encoded);
    auto decoded = base64Decode(encoded);
    ASSERT_TRUE(decoded.ok()) << decoded.error();
    EXPECT_EQ(*decoded, bytesOf(plain));
  }
}

TEST(Base64Test, FullAlphabetAndHighBytes) {
  // Bytes 0x00..0xff in sequence exercise every 6-bit group, including '+' and '/'.
  std::vector<uint8_t> all(256);
  for (int i = 0; i < 256; ++i) all[i] = uint8_t(i);
  std::string encoded = base64Encode(all);
  EXPECT_EQ(encoded.size(), 344u);
  EXPECT_EQ(encoded.substr(0, 8), "AAECAwQF");
  EXPECT_EQ(encoded.substr(encoded.size() - 8), "/P3+/w==");
  auto decoded = base64Decode(encoded);
  ASSERT_TRUE(decoded.ok()) << decoded.error();
  EXPECT_EQ(*decoded, all);
  EXPECT_EQ(base64Encode({0xfb, 0xff, 0xbf}), "+/+/");
}

TEST(Base64Test, VoxelPayloadSize) {
  // A block's payload: 4096 bytes -> 5464 characters (4096 = 3 * 1365 + 1: two '=').
  std::vector<uint8_t> voxels(4096, 0);
  voxels[4095] = 7;
  std::string encoded = base64Encode(voxels);
  EXPECT_EQ(encoded.size(), 5464u);
  EXPECT_EQ(encoded.substr(encoded.size() - 4), "Bw==");
  auto decoded = base64Decode(encoded);
  ASSERT_TRUE(decoded.ok());
  EXPECT_EQ(*decoded, voxels);
}

TEST(Base64Test, RandomRoundTrip) {
  std::mt19937 rng(12345);
  std::uniform_int_distribution<int> byte(0, 255);
  for (size_t length = 0; length < 300; ++length) {
    for (int rep = 0; rep < 3; ++rep) {
      std::vector<uint8_t> bytes(length);
      for (uint8_t& b : bytes) b = uint8_t(byte(rng));
      std::string encoded = base64Encode(bytes);
      ASSERT_EQ(encoded.size(), (length + 2) / 3 * 4);
      ASSERT_EQ(encoded.find_first_not_of(
                    "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/="),
                std::string::npos);
      auto decoded = base64Decode(encoded);
      ASSERT_TRUE(decoded.ok()) << decoded.error();
      ASSERT_EQ(*decoded, bytes) << "length " << length;
    }
  }
}

TEST(Base64Test, RefusesBadLength) {
  expectRefused("Z", "length 1");
  expectRefused("Zm9", "length 3");
  expectRefused("Zm9vY", "length 5");
  expectRefused("Zm9v=", "length 5");
  expectRefused("Zg=", "length 3");
  expectRefused("Zm9v\n", "length 5");  // no line breaks
}

TEST(Base64Test, RefusesBadCharacterWithOffset) {
  expectRefused("Zm9v!A==", "offset 4");
  expectRefused("Zm9vYmFy-_==", "offset 8");  // URL-safe alphabet is not accepted
  expectRefused("Zm 9", "offset 2");
  expectRefused("Zm9\n", "offset 3");
  expectRefused(std::string("Zm9v\xff"
                            "AAA"),
                "offset 4");
  expectRefused(std::string("AA\0A", 4), "offset 2");
  std::string long_text(4000, 'A');
  long_text[2345] = '.';
  expectRefused(long_text, "offset 2345");
}

TEST(Base64Test, RefusesMisplacedPadding) {
  expectRefused("====", "offset 0");
  expectRefused("Z===", "offset 1");      // at most two '='
  expectRefused("Zm=v", "offset 2");      // '=' followed by data
  expectRefused("Zg==Zg==", "offset 2");  // padding only in the last group
  expectRefused("Zm8=Zm9v", "offset 3");
  expectRefused("=m9v", "offset 0");
}

}  // namespace
}  // namespace rdm
