// BC6H's block format, shared by the decoder (bc6h.cpp) and the encoder (bc6h_encode.cpp): the
// mode table, each mode's bit layout, the 2-region partitions, and the unquantization steps, all
// as the Khronos Data Format Specification's BPTC chapter states them (unsigned float only).
#pragma once

#include <array>
#include <cstdint>

#include "rdm/image/bc6h.h"

namespace rdm::bc6h {

// Endpoint variables of the block description: endpoint e (0..3), channel c (0..2) is
// variable 3 e + c; kPartitionBits stands for PB.
enum Var : uint8_t { R0, G0, B0, R1, G1, B1, R2, G2, B2, R3, G3, B3, kPartitionBits };

// One run "v^from..to" of the block description: consecutive block bits fill bit `to` of v
// first and step towards bit `from` (from >= to: increasing bits; from < to: reversed).
struct Field {
  uint8_t var, from, to;
  constexpr int count() const { return from >= to ? from - to + 1 : to - from + 1; }
};

constexpr int kMaxFields = 24;

struct ModeInfo {
  int number;        // Microsoft's 1..14
  uint8_t code;      // the mode bits' value
  int code_bits;     // 2 or 5
  int regions;       // 1 or 2
  bool transformed;  // endpoints 1..3 stored as deltas from endpoint 0
  int endpoint_bits;
  std::array<int, 3> delta_bits;  // stored bits of endpoints 1..3 per channel
  int field_count;
  std::array<Field, kMaxFields> fields;  // after the mode bits, lowest block bit first
};

constexpr int kModeCount = 14;
extern const std::array<ModeInfo, kModeCount> kModes;  // index = number - 1

// Index of the mode whose code starts `block`, or -1 for a reserved code.
int modeIndexOf(const Bc6hBlock& block);

constexpr int kPartitionCount = 32;
int subsetOf(int partition, int texel);  // 0 or 1
int anchorOf(int partition);             // the texel holding subset 1's anchor index

inline constexpr std::array<int, 8> kWeights3 = {0, 9, 18, 27, 37, 46, 55, 64};
inline constexpr std::array<int, 16> kWeights4 = {0,  4,  9,  13, 17, 21, 26, 30,
                                                  34, 38, 43, 47, 51, 55, 60, 64};

// First bit of the indices, and the bits per index, of a 1- or 2-region block.
constexpr int indexStart(int regions) {
  return regions == 1 ? 65 : 82;
}
constexpr int indexBits(int regions) {
  return regions == 1 ? 4 : 3;
}
constexpr int weightOf(int regions, int index) {
  return regions == 1 ? kWeights4[index] : kWeights3[index];
}

// Little-endian bit access to a block; count <= 32.
uint32_t readBits(const Bc6hBlock& block, int start, int count);
void writeBits(Bc6hBlock& block, int start, int count, uint32_t value);

// An endpoint channel of `bits` bits widened to 16 (the specification's unsigned unquantize).
constexpr int unquantize(int value, int bits) {
  if (bits >= 15) return value;
  if (value == 0) return 0;
  if (value == (1 << bits) - 1) return 0xFFFF;
  return ((value << 15) + 0x4000) >> (bits - 1);
}

// Interpolates two unquantized endpoints with a 6-bit weight and applies the final unsigned
// unquantization: the result is the texel's half-float bit pattern (at most 0x7BFF).
constexpr int interpolateToHalf(int a, int b, int weight) {
  const int interpolated = ((64 - weight) * a + weight * b + 32) >> 6;
  return (interpolated * 31) >> 6;
}

// The endpoint values of a block after undoing the delta transform: ep[e][c], each of
// endpoint_bits bits, before unquantization.
using EndpointValues = std::array<std::array<int, 3>, 4>;
// Reads the stored endpoint fields (and the partition) of a block of mode `mode`.
void readEndpoints(const Bc6hBlock& block, const ModeInfo& mode, EndpointValues& stored,
                   int& partition);
// The inverse of readEndpoints: writes the mode bits, fields and partition into `block`.
void writeEndpoints(Bc6hBlock& block, const ModeInfo& mode, const EndpointValues& stored,
                    int partition);
// Stored fields to endpoint values: sign-extends deltas and adds endpoint 0, wrapping at
// endpoint_bits, for transformed modes; a copy otherwise.
EndpointValues untransform(const ModeInfo& mode, const EndpointValues& stored);

}  // namespace rdm::bc6h
