// BC6H_UFLOAT's block format (docs/bc6h.md), shared by the C++ codec (libs/image/src/bc6h_*.cpp)
// and the Vulkan encoder (shaders/bc6h_encode.comp): the 14 modes' tables and bit layouts, the
// 32 two-region partitions and anchors, the interpolation weights, unquantization, the input
// contract (float bits to half bits) and the packing of a block's fields into 128 bits.
// Everything is 32-bit integer arithmetic, so every device computes the same bits. Written in
// the common subset of GLSL 4.50 and C++ (rdm_shared.h's conventions).
//
// Modes are indexed 0..13 here (Microsoft's mode number minus 1). Endpoint variable 3 e + c is
// endpoint e (0..3), channel c (0..2); variable 12 is the partition number ("partition" is a
// reserved word in GLSL, so variables are named "part").
#ifndef RDM_BC6H_H
#define RDM_BC6H_H

#include "rdm_shared.h"

#ifdef __cplusplus
namespace rdm::shared {
#define RDM_FN constexpr  // the C++ codec's static_asserts use the tables and functions
#define RDM_CONST constexpr
#define RDM_INOUT(T) T&
#else
#define RDM_FN
#define RDM_CONST const
#define RDM_INOUT(T) inout T
#endif

RDM_CONST int kBc6hModeCount = 14;
RDM_CONST int kBc6hPartitionCount = 32;
RDM_CONST int kBc6hPartitionVar = 12;  // the field variable of the partition number
RDM_CONST int kBc6hMaxHalf = 0x7BFF;   // 65504, the largest finite half

// Per mode: the mode bits' value, their count, regions, whether endpoints 1..3 are stored as
// deltas from endpoint 0, endpoint bits, and stored bits of endpoints 1..3 per channel.
RDM_CONST uint kBc6hModeCode[14] = {0x00u, 0x01u, 0x02u, 0x06u, 0x0Au, 0x0Eu, 0x12u,
                                    0x16u, 0x1Au, 0x1Eu, 0x03u, 0x07u, 0x0Bu, 0x0Fu};
RDM_CONST int kBc6hModeCodeBits[14] = {2, 2, 5, 5, 5, 5, 5, 5, 5, 5, 5, 5, 5, 5};
RDM_CONST int kBc6hModeRegions[14] = {2, 2, 2, 2, 2, 2, 2, 2, 2, 2, 1, 1, 1, 1};
RDM_CONST bool kBc6hModeTransformed[14] = {true, true, true, true, true,  true,  true,
                                           true, true, false, false, true, true, true};
RDM_CONST int kBc6hEndpointBits[14] = {10, 7, 11, 11, 11, 9, 8, 8, 8, 6, 10, 11, 12, 16};
RDM_CONST int kBc6hDeltaBits[42] = {5, 5, 5, 6, 6, 6, 5, 4, 4, 4, 5, 4, 4, 4, 5,
                                    5, 5, 5, 6, 5, 5, 5, 6, 5, 5, 5, 6, 6, 6, 6,
                                    10, 10, 10, 9, 9, 9, 8, 8, 8, 4, 4, 4};

// Each mode's bit layout after the mode bits, from the Khronos "Block descriptions" table:
// fields kBc6hFieldStart[m] .. kBc6hFieldStart[m + 1] - 1 of kBc6hFields, lowest block bit
// first. A field 0xVFT is the run "variable V, bits F..T": consecutive block bits fill bit T
// first and step towards bit F (F >= T: increasing bits; F < T: reversed).
RDM_CONST int kBc6hFieldStart[15] = {0,   20,  44,  63,  84,  105, 125, 145,
                                     167, 189, 213, 219, 228, 237, 246};
RDM_CONST uint kBc6hFields[246] = {
    // mode 1
    0x744u, 0x844u, 0xB44u, 0x090u, 0x190u, 0x290u, 0x340u, 0xA44u, 0x730u, 0x440u,
    0xB00u, 0xA30u, 0x540u, 0xB11u, 0x830u, 0x640u, 0xB22u, 0x940u, 0xB33u, 0xC40u,
    // mode 2
    0x755u, 0xA44u, 0xA55u, 0x060u, 0xB00u, 0xB11u, 0x844u, 0x160u, 0x855u, 0xB22u,
    0x744u, 0x260u, 0xB33u, 0xB55u, 0xB44u, 0x350u, 0x730u, 0x450u, 0xA30u, 0x550u,
    0x830u, 0x650u, 0x950u, 0xC40u,
    // mode 3
    0x090u, 0x190u, 0x290u, 0x340u, 0x0AAu, 0x730u, 0x430u, 0x1AAu, 0xB00u, 0xA30u,
    0x530u, 0x2AAu, 0xB11u, 0x830u, 0x640u, 0xB22u, 0x940u, 0xB33u, 0xC40u,
    // mode 4
    0x090u, 0x190u, 0x290u, 0x330u, 0x0AAu, 0xA44u, 0x730u, 0x440u, 0x1AAu, 0xA30u,
    0x530u, 0x2AAu, 0xB11u, 0x830u, 0x630u, 0xB00u, 0xB22u, 0x930u, 0x744u, 0xB33u,
    0xC40u,
    // mode 5
    0x090u, 0x190u, 0x290u, 0x330u, 0x0AAu, 0x844u, 0x730u, 0x430u, 0x1AAu, 0xB00u,
    0xA30u, 0x540u, 0x2AAu, 0x830u, 0x630u, 0xB11u, 0xB22u, 0x930u, 0xB44u, 0xB33u,
    0xC40u,
    // mode 6
    0x080u, 0x844u, 0x180u, 0x744u, 0x280u, 0xB44u, 0x340u, 0xA44u, 0x730u, 0x440u,
    0xB00u, 0xA30u, 0x540u, 0xB11u, 0x830u, 0x640u, 0xB22u, 0x940u, 0xB33u, 0xC40u,
    // mode 7
    0x070u, 0xA44u, 0x844u, 0x170u, 0xB22u, 0x744u, 0x270u, 0xB33u, 0xB44u, 0x350u,
    0x730u, 0x440u, 0xB00u, 0xA30u, 0x540u, 0xB11u, 0x830u, 0x650u, 0x950u, 0xC40u,
    // mode 8
    0x070u, 0xB00u, 0x844u, 0x170u, 0x755u, 0x744u, 0x270u, 0xA55u, 0xB44u, 0x340u,
    0xA44u, 0x730u, 0x450u, 0xA30u, 0x540u, 0xB11u, 0x830u, 0x640u, 0xB22u, 0x940u,
    0xB33u, 0xC40u,
    // mode 9
    0x070u, 0xB11u, 0x844u, 0x170u, 0x855u, 0x744u, 0x270u, 0xB55u, 0xB44u, 0x340u,
    0xA44u, 0x730u, 0x440u, 0xB00u, 0xA30u, 0x550u, 0x830u, 0x640u, 0xB22u, 0x940u,
    0xB33u, 0xC40u,
    // mode 10
    0x050u, 0xA44u, 0xB00u, 0xB11u, 0x844u, 0x150u, 0x755u, 0x855u, 0xB22u, 0x744u,
    0x250u, 0xA55u, 0xB33u, 0xB55u, 0xB44u, 0x350u, 0x730u, 0x450u, 0xA30u, 0x550u,
    0x830u, 0x650u, 0x950u, 0xC40u,
    // mode 11
    0x090u, 0x190u, 0x290u, 0x390u, 0x490u, 0x590u,
    // mode 12
    0x090u, 0x190u, 0x290u, 0x380u, 0x0AAu, 0x480u, 0x1AAu, 0x580u, 0x2AAu,
    // mode 13
    0x090u, 0x190u, 0x290u, 0x370u, 0x0ABu, 0x470u, 0x1ABu, 0x570u, 0x2ABu,
    // mode 14
    0x090u, 0x190u, 0x290u, 0x330u, 0x0AFu, 0x430u, 0x1AFu, 0x530u, 0x2AFu};

// The first 32 partitions of the BPTC two-subset table (bit t: the subset of texel t) and the
// texel holding each partition's subset-1 anchor index.
RDM_CONST uint kBc6hPartitions[32] = {
    0xCCCCu, 0x8888u, 0xEEEEu, 0xECC8u, 0xC880u, 0xFEECu, 0xFEC8u, 0xEC80u,
    0xC800u, 0xFFECu, 0xFE80u, 0xE800u, 0xFFE8u, 0xFF00u, 0xFFF0u, 0xF000u,
    0xF710u, 0x008Eu, 0x7100u, 0x08CEu, 0x008Cu, 0x7310u, 0x3100u, 0x8CCEu,
    0x088Cu, 0x3110u, 0x6666u, 0x366Cu, 0x17E8u, 0x0FF0u, 0x718Eu, 0x399Cu};
RDM_CONST int kBc6hAnchors[32] = {15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15,
                                  15, 15, 15, 15, 15, 15, 2,  8,  2,  2,  8,
                                  8,  15, 2,  8,  2,  2,  8,  8,  2,  2};

// Interpolation weights (of 64) of 4-bit (one region) and 3-bit (two regions) indices.
RDM_CONST int kBc6hWeights4[16] = {0, 4, 9, 13, 17, 21, 26, 30, 34, 38, 43, 47, 51, 55, 60, 64};
RDM_CONST int kBc6hWeights3[8] = {0, 9, 18, 27, 37, 46, 55, 64};

RDM_FN int bc6hIndexStart(int regions) { return regions == 1 ? 65 : 82; }
RDM_FN int bc6hIndexBits(int regions) { return regions == 1 ? 4 : 3; }
RDM_FN int bc6hWeight(int regions, int index) {
  return regions == 1 ? kBc6hWeights4[index] : kBc6hWeights3[index];
}
RDM_FN int bc6hSubset(int regions, int part, int texel) {
  return regions == 1 ? 0 : int((kBc6hPartitions[part] >> uint(texel)) & 1u);
}
RDM_FN bool bc6hIsAnchor(int regions, int part, int texel) {
  return texel == 0 || (regions == 2 && texel == kBc6hAnchors[part]);
}

// An endpoint channel of `bits` bits widened to 16 (the specification's unsigned unquantize).
RDM_FN int bc6hUnquantize(int value, int bits) {
  if (bits >= 15) return value;
  if (value == 0) return 0;
  if (value == (1 << bits) - 1) return 0xFFFF;
  return ((value << 15) + 0x4000) >> (bits - 1);
}

// Interpolates two unquantized endpoints with a 6-bit weight and applies the final unsigned
// unquantization: the texel's half bit pattern (at most 0x7BFF).
RDM_FN int bc6hInterpolate(int a, int b, int weight) {
  return ((((64 - weight) * a + weight * b + 32) >> 6) * 31) >> 6;
}
RDM_FN ivec3 bc6hInterpolate3(ivec3 a, ivec3 b, int weight) {
  return ((((64 - weight) * a + weight * b + 32) >> 6) * 31) >> 6;
}

// The input contract (bc6h.h) on a float's bits: NaN, zeros and negatives give 0, values
// from 65504 up (+infinity included) give 65504, the rest round to the nearest half, ties to
// even. The result is the half's bit pattern.
RDM_FN int bc6hInputHalf(uint f) {
  if ((f & 0x80000000u) != 0u || f > 0x7F800000u) return 0;  // negatives and NaNs
  if (f >= 0x477FE000u) return kBc6hMaxHalf;                   // 65504 and above
  int e = int(f >> 23);
  if (e < 102) return 0;  // below 2^-25: rounds to zero
  uint m = (f & 0x7FFFFFu) | 0x800000u;
  int shift = e >= 113 ? 13 : 126 - e;  // normal halves keep 10 mantissa bits
  uint kept = m >> uint(shift);
  uint rest = m & ((1u << uint(shift)) - 1u), halfway = 1u << uint(shift - 1);
  if (rest > halfway || (rest == halfway && (kept & 1u) != 0u)) kept += 1u;
  // A normal half's implicit bit adds one to its biased exponent e - 112; a carry out of the
  // mantissa moves into the exponent.
  return e >= 113 ? int(uint(e - 113) << 10) + int(kept) : int(kept);
}

// Sets `count` bits of `block` from bit `start` to the low bits of `value`; the bits must be 0.
RDM_FN void bc6hPutBits(RDM_INOUT(uvec4) block, int start, int count, uint value) {
  for (int i = 0; i < count; ++i) {
    int bit = start + i;
    block[bit >> 5] |= ((value >> uint(i)) & 1u) << uint(bit & 31);
  }
}

#ifdef __cplusplus
}  // namespace rdm::shared
#undef RDM_FN
#undef RDM_CONST
#undef RDM_INOUT
#endif
#endif  // RDM_BC6H_H
