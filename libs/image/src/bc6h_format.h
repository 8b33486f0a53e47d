// BC6H's block format for the decoder (bc6h.cpp): the mode table, each mode's bit layout, the
// 2-region partitions, and the unquantization steps, as the Khronos Data Format Specification's
// BPTC chapter states them (unsigned float only). The tables and arithmetic are those of
// shaders/shared/rdm_bc6h.h, which the encoder (CPU and Vulkan) uses; this is their C++ view.
#pragma once

#include <array>
#include <cstdint>

#include "rdm/image/bc6h.h"
#include "shared/rdm_bc6h.h"

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

// First bit of the indices, and the bits per index, of a 1- or 2-region block.
constexpr int indexStart(int regions) {
  return shared::bc6hIndexStart(regions);
}
constexpr int indexBits(int regions) {
  return shared::bc6hIndexBits(regions);
}
constexpr int weightOf(int regions, int index) {
  return shared::bc6hWeight(regions, index);
}

// Little-endian bit access to a block; count <= 32.
uint32_t readBits(const Bc6hBlock& block, int start, int count);

constexpr int unquantize(int value, int bits) {
  return shared::bc6hUnquantize(value, bits);
}
constexpr int interpolateToHalf(int a, int b, int weight) {
  return shared::bc6hInterpolate(a, b, weight);
}

// The endpoint values of a block after undoing the delta transform: ep[e][c], each of
// endpoint_bits bits, before unquantization.
using EndpointValues = std::array<std::array<int, 3>, 4>;
// Reads the stored endpoint fields (and the partition) of a block of mode `mode`.
void readEndpoints(const Bc6hBlock& block, const ModeInfo& mode, EndpointValues& stored,
                   int& partition);
// Stored fields to endpoint values: sign-extends deltas and adds endpoint 0, wrapping at
// endpoint_bits, for transformed modes; a copy otherwise.
EndpointValues untransform(const ModeInfo& mode, const EndpointValues& stored);

}  // namespace rdm::bc6h
