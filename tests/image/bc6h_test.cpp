#include "rdm/image/bc6h.h"

#include <Imath/half.h>
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "shared/rdm_bc6h_encode.h"

namespace rdm {
namespace {

// Sets `count` block bits from `start`, lowest bit of `value` first: the spec's bit tables.
void putBits(Bc6hBlock& block, int start, int count, uint32_t value) {
  for (int i = 0; i < count; ++i)
    if ((value >> i) & 1) block[(start + i) / 8] |= uint8_t(1u << ((start + i) % 8));
}

float roundToHalf(float v) {
  return float(Imath::half(v));
}

Bc6hTexels constantTexels(float r, float g, float b) {
  Bc6hTexels texels;
  for (auto& t : texels) t = {r, g, b};
  return texels;
}

// Squared error in half bits of `block` against `texels` (after the input clamp).
int64_t halfBitError(const Bc6hBlock& block, const Bc6hTexels& texels) {
  const Bc6hTexels decoded = decodeBc6hBlock(block);
  int64_t error = 0;
  for (int t = 0; t < 16; ++t)
    for (int c = 0; c < 3; ++c) {
      const int64_t d = int64_t(Imath::half(decoded[t][c]).bits()) -
                        int64_t(Imath::half(bc6hClampInput(texels[t][c])).bits());
      error += d * d;
    }
  return error;
}

float maxRelativeError(const Bc6hTexels& decoded, const Bc6hTexels& source) {
  float worst = 0;
  for (int t = 0; t < 16; ++t)
    for (int c = 0; c < 3; ++c)
      worst = std::max(worst, std::abs(decoded[t][c] - source[t][c]) / source[t][c]);
  return worst;
}

// Mode 11 (Khronos mode 3): bits 0..4 = 00011, then R0, G0, B0, R1, G1, B1 at 10 bits each
// from bit 5; 4-bit indices from bit 65, texel 0's with 3 bits.
TEST(Bc6hDecode, Mode11MatchesHandComputedValues) {
  Bc6hBlock block{};
  putBits(block, 0, 5, 0x03);
  const uint32_t endpoints[6] = {0, 512, 1023, 1023, 512, 0};
  for (int i = 0; i < 6; ++i) putBits(block, 5 + 10 * i, 10, endpoints[i]);
  putBits(block, 65, 3, 0);   // texel 0: weight 0
  putBits(block, 68, 4, 15);  // texel 1: weight 64
  putBits(block, 72, 4, 5);   // texel 2: weight 21
  EXPECT_EQ(bc6hBlockMode(block), 11);
  const Bc6hTexels texels = decodeBc6hBlock(block);
  // Unquantized: 0 -> 0, 512 -> 32800, 1023 -> 0xFFFF; half = (interpolated * 31) >> 6.
  EXPECT_EQ(texels[0][0], 0.0f);
  EXPECT_EQ(texels[0][1], 1.5146484375f);  // 32800 -> 0x3E0F
  EXPECT_EQ(texels[0][2], 65504.0f);       // 0xFFFF -> 0x7BFF
  EXPECT_EQ(texels[1][0], 65504.0f);
  EXPECT_EQ(texels[1][1], 1.5146484375f);
  EXPECT_EQ(texels[1][2], 0.0f);
  EXPECT_EQ(texels[2][0], 0.036621094f);  // (21 * 65535 + 32) >> 6 = 21504 -> 0x28B0
  EXPECT_EQ(texels[2][1], 1.5146484375f);
  EXPECT_EQ(texels[2][2], 58.46875f);  // (43 * 65535 + 32) >> 6 = 44031 -> 0x534F
  for (int t = 3; t < 16; ++t) EXPECT_EQ(texels[t][0], 0.0f) << t;
}

// Mode 1 (Khronos mode 0), partition 0 (texels with x >= 2 in subset 1, anchor texel 15):
// 10-bit E0, 5-bit deltas; bit positions from the spec's "Interpretation of lower bits" table.
TEST(Bc6hDecode, Mode1MatchesHandComputedValues) {
  Bc6hBlock block{};
  // E0 = (500, 500, 500); deltas E1 = (10, -1, 0), E2 = (-16, 15, 5), E3 = (3, -5, 1).
  const uint32_t g2 = 15, b2 = 5, b3 = 1, g3 = 0x1B;
  putBits(block, 2, 1, g2 >> 4);
  putBits(block, 3, 1, b2 >> 4);
  putBits(block, 4, 1, b3 >> 4);
  putBits(block, 5, 10, 500);
  putBits(block, 15, 10, 500);
  putBits(block, 25, 10, 500);
  putBits(block, 35, 5, 10);        // R1
  putBits(block, 40, 1, g3 >> 4);   // G3^4
  putBits(block, 41, 4, g2 & 0xF);  // G2^3..0
  putBits(block, 45, 5, 0x1F);      // G1
  putBits(block, 50, 1, b3 & 1);    // B3^0
  putBits(block, 51, 4, g3 & 0xF);  // G3^3..0
  putBits(block, 55, 5, 0);         // B1
  putBits(block, 60, 1, b3 >> 1);   // B3^1
  putBits(block, 61, 4, b2 & 0xF);  // B2^3..0
  putBits(block, 65, 5, 0x10);      // R2
  putBits(block, 70, 1, b3 >> 2);   // B3^2
  putBits(block, 71, 5, 3);         // R3
  putBits(block, 76, 1, b3 >> 3);   // B3^3
  putBits(block, 77, 5, 0);         // partition 0
  putBits(block, 82, 2, 0);         // texel 0 (anchor of subset 0)
  putBits(block, 84, 3, 4);         // texel 1: weight 37
  putBits(block, 90, 3, 7);         // texel 3: weight 64
  putBits(block, 126, 2, 3);        // texel 15 (anchor of subset 1): weight 27
  EXPECT_EQ(bc6hBlockMode(block), 1);
  const Bc6hTexels texels = decodeBc6hBlock(block);
  // Unquantized 10-bit x is 64 x + 32: E0 = 32032, E1 = (32672, 31968, 32032),
  // E2 = (31008, 32992, 32352), E3 = (32224, 31712, 32096).
  for (int c = 0; c < 3; ++c) EXPECT_EQ(texels[0][c], 1.1513671875f);  // 15515
  EXPECT_EQ(texels[1][0], 1.326171875f);                               // 15694
  EXPECT_EQ(texels[1][1], 1.1337890625f);                              // 15497
  EXPECT_EQ(texels[1][2], 1.1513671875f);
  EXPECT_EQ(texels[2][0], 0.83349609375f);   // E2: 15019
  EXPECT_EQ(texels[2][1], 1.60546875f);      // 15980
  EXPECT_EQ(texels[2][2], 1.302734375f);     // 15670
  EXPECT_EQ(texels[3][0], 1.2421875f);       // E3: 15608
  EXPECT_EQ(texels[3][1], 1.0f);             // 15360
  EXPECT_EQ(texels[3][2], 1.181640625f);     // 15546
  EXPECT_EQ(texels[15][0], 0.95458984375f);  // 15267
  EXPECT_EQ(texels[15][1], 1.349609375f);    // 15718
  EXPECT_EQ(texels[15][2], 1.251953125f);    // 15618
  EXPECT_EQ(texels[4][0], 1.1513671875f);
}

// Mode 14 (Khronos mode 15): 16-bit E0 whose bits 10..15 are stored reversed (R0^10..15),
// 4-bit deltas.
TEST(Bc6hDecode, Mode14ReadsReversedEndpointBits) {
  Bc6hBlock block{};
  putBits(block, 0, 5, 0x0F);
  const uint32_t e0[3] = {33000, 1000, 65535};
  const uint32_t delta[3] = {0x8, 0x7, 0x0};  // -8, +7, 0
  for (int c = 0; c < 3; ++c) {
    putBits(block, 5 + 10 * c, 10, e0[c] & 0x3FF);
    putBits(block, 35 + 10 * c, 4, delta[c]);
    for (int i = 0; i < 6; ++i) putBits(block, 39 + 10 * c + i, 1, (e0[c] >> (15 - i)) & 1);
  }
  putBits(block, 68, 4, 15);  // texel 1: weight 64
  EXPECT_EQ(bc6hBlockMode(block), 14);
  const Bc6hTexels texels = decodeBc6hBlock(block);
  EXPECT_EQ(texels[0][0], 1.609375f);                       // 33000 * 31 >> 6 = 15984
  EXPECT_EQ(texels[0][1], 484.0f * std::ldexp(1.0f, -24));  // subnormal 484
  EXPECT_EQ(texels[0][2], 65504.0f);
  EXPECT_EQ(texels[1][0], 1.60546875f);                     // 32992 -> 15980
  EXPECT_EQ(texels[1][1], 487.0f * std::ldexp(1.0f, -24));  // 1007 -> 487
  EXPECT_EQ(texels[1][2], 65504.0f);
}

// Mode 10 (Khronos mode 30): two regions, 6-bit endpoints stored as they are, with the most
// scattered layout; positions from the spec's per-bit table. All indices 0: texel 0 shows E0 and
// texel 2 (subset 1 of partition 0) shows E2.
TEST(Bc6hDecode, Mode10MatchesHandComputedValues) {
  Bc6hBlock block{};
  putBits(block, 0, 5, 0x1E);
  const uint32_t g2 = 45, b2 = 62;
  putBits(block, 5, 6, 33);         // R0
  putBits(block, 14, 1, b2 >> 4);   // B2^4
  putBits(block, 15, 6, 10);        // G0
  putBits(block, 21, 1, g2 >> 5);   // G2^5
  putBits(block, 22, 1, b2 >> 5);   // B2^5
  putBits(block, 24, 1, g2 >> 4);   // G2^4
  putBits(block, 25, 6, 50);        // B0
  putBits(block, 41, 4, g2 & 0xF);  // G2^3..0
  putBits(block, 61, 4, b2 & 0xF);  // B2^3..0
  putBits(block, 65, 6, 20);        // R2
  EXPECT_EQ(bc6hBlockMode(block), 10);
  const Bc6hTexels texels = decodeBc6hBlock(block);
  // Unquantized 6-bit x is 1024 x + 512; half = (unquantized * 31) >> 6.
  EXPECT_EQ(texels[0][0], 2.453125f);             // 33 -> 16616
  EXPECT_EQ(texels[0][1], 0.00106048583984375f);  // 10 -> 5208
  EXPECT_EQ(texels[0][2], 748.0f);                // 50 -> 25048
  EXPECT_EQ(texels[2][0], 0.0301513671875f);      // 20 -> 10168
  EXPECT_EQ(texels[2][1], 133.0f);                // 45 -> 22568
  EXPECT_EQ(texels[2][2], 41728.0f);              // 62 -> 31000
  EXPECT_EQ(texels[15][2], 41728.0f);
}

TEST(Bc6hDecode, ReservedModesDecodeToBlack) {
  for (uint8_t code : {0x13, 0x17, 0x1B, 0x1F}) {
    Bc6hBlock block{};
    block.fill(0xFF);
    block[0] = uint8_t(0xE0 | code);
    EXPECT_EQ(bc6hBlockMode(block), 0);
    for (const auto& texel : decodeBc6hBlock(block))
      for (float v : texel) EXPECT_EQ(v, 0.0f);
  }
}

TEST(Bc6hEncode, ConstantBlocksRoundTripExactlyToHalf) {
  const float values[][3] = {{1, 1, 1},
                             {0.5f, 2.0f, 3.14159f},
                             {1e-3f, 1e3f, 7.0f},
                             {3e-6f, 0, 1e-7f},
                             {65504, 65504, 65504},
                             {0.2f, 5.0f, 700.0f},
                             {12345.6f, 1e-4f, 0.75f}};
  for (Bc6hModeSet modes : {Bc6hModeSet::kOneRegion, Bc6hModeSet::kAll})
    for (const auto& v : values) {
      const Bc6hTexels decoded =
          decodeBc6hBlock(encodeBc6hBlock(constantTexels(v[0], v[1], v[2]), modes));
      for (const auto& texel : decoded)
        for (int c = 0; c < 3; ++c) EXPECT_EQ(texel[c], roundToHalf(v[c])) << v[c];
    }
}

TEST(Bc6hEncode, ZerosStayZeroInEveryModeSet) {
  for (Bc6hModeSet modes : {Bc6hModeSet::kMode11, Bc6hModeSet::kOneRegion, Bc6hModeSet::kAll})
    for (const auto& texel : decodeBc6hBlock(encodeBc6hBlock(constantTexels(0, 0, 0), modes)))
      for (float v : texel) EXPECT_EQ(v, 0.0f);
}

TEST(Bc6hEncode, ClampsNegativeNanAndOverflow) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  EXPECT_EQ(bc6hClampInput(-1.0f), 0.0f);
  EXPECT_EQ(bc6hClampInput(nan), 0.0f);
  EXPECT_EQ(bc6hClampInput(-inf), 0.0f);
  EXPECT_EQ(bc6hClampInput(inf), 65504.0f);
  EXPECT_EQ(bc6hClampInput(1e6f), 65504.0f);
  EXPECT_EQ(bc6hClampInput(2.5f), 2.5f);
  const Bc6hTexels decoded = decodeBc6hBlock(encodeBc6hBlock(constantTexels(-3.0f, nan, 1e9f)));
  for (const auto& texel : decoded) {
    EXPECT_EQ(texel[0], 0.0f);
    EXPECT_EQ(texel[1], 0.0f);
    EXPECT_EQ(texel[2], 65504.0f);
  }
  Bc6hTexels mixed = constantTexels(1, 1, 1);
  mixed[5] = {-inf, nan, -0.0f};
  const Bc6hTexels out = decodeBc6hBlock(encodeBc6hBlock(mixed));
  for (int c = 0; c < 3; ++c) EXPECT_EQ(out[5][c], 0.0f);
  EXPECT_NEAR(out[0][0], 1.0f, 1e-3f);
}

float meanRelativeError(const Bc6hTexels& decoded, const Bc6hTexels& source) {
  float sum = 0;
  for (int t = 0; t < 16; ++t)
    for (int c = 0; c < 3; ++c) sum += std::abs(decoded[t][c] - source[t][c]) / source[t][c];
  return sum / 48.0f;
}

// A diagonal gradient between two colours, as lit surfaces mostly are. Its 7 levels fall
// between the 16 weights, so each texel may be off by up to a weight step of the range (measured
// 2.6 % at most with mode 11 alone, 1.8 % with more modes).
TEST(Bc6hEncode, GradientsStayWithinThreePercent) {
  Bc6hTexels texels;
  for (int t = 0; t < 16; ++t) {
    const float s = float(t % 4 + t / 4) / 6.0f;
    texels[t] = {1.0f + s, 0.5f + 0.25f * s, 2.0f + 2.0f * s};
  }
  for (Bc6hModeSet modes : {Bc6hModeSet::kMode11, Bc6hModeSet::kOneRegion, Bc6hModeSet::kAll}) {
    const Bc6hTexels decoded = decodeBc6hBlock(encodeBc6hBlock(texels, modes));
    EXPECT_LT(maxRelativeError(decoded, texels), 0.03f);
    EXPECT_LT(meanRelativeError(decoded, texels), 0.01f);
  }
}

// An exponential ramp over 6 orders of magnitude (1e-3 .. 1e3) across a 64 x 4 image, each
// channel a quarter texel ahead of the previous: every block spans a factor of 2.4, which BC6H
// interpolates linearly within each octave. Bounds: 4 % relative error per value (measured
// 3.7 %) and 1 % on average (measured 0.81 %).
TEST(Bc6hEncode, HdrRampAcrossSixOrdersOfMagnitude) {
  Image image(64, 4, 3);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 64; ++x)
      for (int c = 0; c < 3; ++c)
        image.at(x, y, c) = std::pow(10.0f, -3.0f + 6.0f * (float(x) + 0.25f * c) / 63.0f);
  for (Bc6hModeSet modes : {Bc6hModeSet::kOneRegion, Bc6hModeSet::kAll}) {
    Expected<Bc6hImage> encoded = encodeBc6h(image, {modes, 1});
    ASSERT_TRUE(encoded.ok());
    Expected<Image> decoded = decodeBc6h(*encoded);
    ASSERT_TRUE(decoded.ok());
    double sum = 0;
    for (size_t i = 0; i < image.pixels.size(); ++i) {
      const double relative = std::abs(decoded->pixels[i] - image.pixels[i]) / image.pixels[i];
      EXPECT_LT(relative, 0.04) << i;
      sum += relative;
    }
    EXPECT_LT(sum / double(image.pixels.size()), 0.01);
  }
}

// Blocks each constant at 10^k, k = -4 .. 4: the exponent range within one image.
TEST(Bc6hEncode, ConstantBlocksAcrossDecadesRoundTripExactly) {
  Image image(36, 4, 3);
  for (int x = 0; x < 36; ++x)
    for (int y = 0; y < 4; ++y)
      for (int c = 0; c < 3; ++c) image.at(x, y, c) = 3.0f * std::pow(10.0f, float(x / 4 - 4));
  Expected<Image> decoded = decodeBc6h(*encodeBc6h(image));
  ASSERT_TRUE(decoded.ok());
  for (size_t i = 0; i < image.pixels.size(); ++i)
    EXPECT_EQ(decoded->pixels[i], roundToHalf(image.pixels[i])) << i;
}

// A noisy block: every larger mode set keeps an error no larger than the smaller one's, since
// it tries a superset and keeps the lowest.
TEST(Bc6hEncode, LargerModeSetsNeverDoWorse) {
  uint32_t seed = 12345;
  auto next = [&seed] {
    seed = seed * 1664525u + 1013904223u;
    return float(seed >> 8) / float(1 << 24);
  };
  for (int trial = 0; trial < 50; ++trial) {
    Bc6hTexels texels;
    for (auto& t : texels) t = {next() * 4.0f, next() * 0.1f, 1.0f + next()};
    const int64_t mode11 = halfBitError(encodeBc6hBlock(texels, Bc6hModeSet::kMode11), texels);
    const int64_t one = halfBitError(encodeBc6hBlock(texels, Bc6hModeSet::kOneRegion), texels);
    const int64_t all = halfBitError(encodeBc6hBlock(texels, Bc6hModeSet::kAll), texels);
    EXPECT_LE(one, mode11);
    EXPECT_LE(all, one);
  }
}

// Three colours that no line through RGB holds: a flat colour where x < 2 and a ramp between two
// others where x >= 2 (partition 0's split). One region must blend them (measured 9.5 % error at
// worst); a two-region mode keeps every value within 5 % (measured 3.6 %, most of it the 10-bit
// endpoint step of mode 1).
TEST(Bc6hEncode, TwoRegionModesSeparateThreeColours) {
  Bc6hTexels texels;
  for (int t = 0; t < 16; ++t) {
    const float s = float(t / 4) / 3.0f;
    texels[t] = t % 4 < 2 ? std::array<float, 3>{1.0f, 0.9f, 0.8f}
                          : std::array<float, 3>{0.9f - 0.1f * s, 1.0f + 0.2f * s, 1.1f - 0.1f * s};
  }
  const Bc6hBlock block = encodeBc6hBlock(texels, Bc6hModeSet::kAll);
  EXPECT_GE(bc6hBlockMode(block), 1);
  EXPECT_LE(bc6hBlockMode(block), 10);
  EXPECT_LT(maxRelativeError(decodeBc6hBlock(block), texels), 0.05f);
  EXPECT_GT(
      maxRelativeError(decodeBc6hBlock(encodeBc6hBlock(texels, Bc6hModeSet::kOneRegion)), texels),
      0.08f);
}

// The shared encoder's float-to-half conversion (integer code, so the GPU's agrees) is the
// input contract followed by Imath's round-to-nearest-even, for every kind of float: specials,
// both sides of every half rounding boundary in range, and random bit patterns.
TEST(Bc6hEncode, InputHalfIsTheContractRoundedToNearestEven) {
  auto expected = [](uint32_t bits) {
    return int(Imath::half(bc6hClampInput(std::bit_cast<float>(bits))).bits());
  };
  std::vector<uint32_t> cases = {0u,          0x80000000u, 0x7F800000u, 0xFF800000u, 0x7FC00000u,
                                 0xFFC00000u, 0x7F800001u, 0x00000001u, 0x477FE000u, 0x477FEFFFu,
                                 0x477FF000u, 0x47800000u, 0x33000000u, 0x33000001u, 0x32FFFFFFu};
  for (uint32_t h = 1; h <= 0x7BFFu; ++h) {
    const uint32_t f =
        std::bit_cast<uint32_t>(float(Imath::half(Imath::half::FromBits, uint16_t(h))));
    const uint32_t below =
        std::bit_cast<uint32_t>(float(Imath::half(Imath::half::FromBits, uint16_t(h - 1))));
    const uint32_t mid = below + (f - below) / 2;  // the tie between two halves
    for (uint32_t b : {f, f - 1, f + 1, mid - 1, mid, mid + 1}) cases.push_back(b);
  }
  std::mt19937 rng(7);
  for (int i = 0; i < 200000; ++i) cases.push_back(uint32_t(rng()));
  for (uint32_t bits : cases) ASSERT_EQ(shared::bc6hInputHalf(bits), expected(bits)) << bits;
}

// The shared encoder's packing (shared::bc6hPack) read back by the C++ decoder: random endpoint
// values, partitions and indices in every mode decode to the palette they define.
TEST(Bc6hEncode, PackedFieldsOfEveryModeDecodeToTheirPalette) {
  std::mt19937 rng(11);
  for (int mode = 0; mode < shared::kBc6hModeCount; ++mode)
    for (int trial = 0; trial < 200; ++trial) {
      shared::Bc6hCandidate c;
      c.mode = mode;
      c.part = int(rng() % 32);
      const int regions = shared::kBc6hModeRegions[mode];
      const int bits = shared::kBc6hEndpointBits[mode];
      for (int e = 0; e < 4; ++e)
        for (int ch = 0; ch < 3; ++ch) {
          const int reach = shared::bc6hDeltaReach(mode, ch);
          int v = int(rng() % (1u << bits));
          if (e > 0 && shared::kBc6hModeTransformed[mode])
            v = std::clamp(c.values[0][ch] + int(rng() % uint32_t(2 * reach)) - reach, 0,
                           (1 << bits) - 1);
          c.values[e][ch] = e < 2 * regions ? v : 0;
        }
      if (regions == 1) c.part = 0;
      for (int t = 0; t < 16; ++t) {
        const int count = 1 << shared::bc6hIndexBits(regions);
        c.indices.k[t] =
            int(rng() % uint32_t(shared::bc6hIsAnchor(regions, c.part, t) ? count / 2 : count));
      }
      ASSERT_TRUE(shared::bc6hStorable(c));
      const glm::uvec4 words = shared::bc6hPack(c);
      Bc6hBlock block;
      for (int b = 0; b < kBc6hBlockBytes; ++b) block[b] = uint8_t(words[b / 4] >> (8 * (b % 4)));
      ASSERT_EQ(bc6hBlockMode(block), mode + 1);
      const Bc6hTexels decoded = decodeBc6hBlock(block);
      for (int t = 0; t < 16; ++t) {
        const int s = shared::bc6hSubset(regions, c.part, t);
        for (int ch = 0; ch < 3; ++ch) {
          const int h =
              shared::bc6hInterpolate(shared::bc6hUnquantize(c.values[2 * s][ch], bits),
                                      shared::bc6hUnquantize(c.values[2 * s + 1][ch], bits),
                                      shared::bc6hWeight(regions, c.indices.k[t]));
          ASSERT_EQ(Imath::half(decoded[t][ch]).bits(), h) << "mode " << mode + 1 << " texel " << t;
        }
      }
    }
}

TEST(Bc6hImage, IgnoresExtraChannelsAndIsThreadIndependent) {
  Image image(16, 8, 4);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 16; ++x) {
      const float scale = 1.0f + 0.1f * float(x) + 0.05f * float(y);
      image.at(x, y, 0) = 0.2f * scale;
      image.at(x, y, 1) = 3.0f * scale;
      image.at(x, y, 2) = 0.7f * scale;
      image.at(x, y, 3) = 1e30f;  // depth: not encoded
    }
  Expected<Bc6hImage> single = encodeBc6h(image, {Bc6hModeSet::kAll, 1});
  Expected<Bc6hImage> threaded = encodeBc6h(image, {Bc6hModeSet::kAll, 2});
  ASSERT_TRUE(single.ok() && threaded.ok());
  EXPECT_EQ(single->blocks.size(), size_t(4 * 2 * kBc6hBlockBytes));
  EXPECT_EQ(single->blocks, threaded->blocks);
  Expected<Image> decoded = decodeBc6h(*single);
  ASSERT_TRUE(decoded.ok());
  EXPECT_EQ(decoded->channels, 3);
  EXPECT_NEAR(decoded->at(15, 7, 1), 3.0f * 2.85f, 0.03f * 3.0f * 2.85f);
}

TEST(Bc6hImage, RefusesSizesThatAreNotWholeBlocks) {
  Expected<Bc6hImage> wide = encodeBc6h(Image(6, 4, 3));
  ASSERT_FALSE(wide.ok());
  EXPECT_EQ(wide.status().field(), "width");
  Expected<Bc6hImage> high = encodeBc6h(Image(4, 2, 3));
  ASSERT_FALSE(high.ok());
  EXPECT_EQ(high.status().field(), "height");
  Expected<Bc6hImage> gray = encodeBc6h(Image(4, 4, 1));
  ASSERT_FALSE(gray.ok());
  EXPECT_EQ(gray.status().field(), "channels");
  Bc6hImage short_blocks{8, 8, std::vector<uint8_t>(3 * kBc6hBlockBytes)};
  Expected<Image> decoded = decodeBc6h(short_blocks);
  ASSERT_FALSE(decoded.ok());
  EXPECT_EQ(decoded.status().field(), "blocks");
}

}  // namespace
}  // namespace rdm
