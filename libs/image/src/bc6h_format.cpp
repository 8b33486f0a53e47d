#include "bc6h_format.h"

namespace rdm::bc6h {
namespace {

constexpr Var P = kPartitionBits;

// The block descriptions of the Khronos BPTC chapter ("Block descriptions for BC6H block
// modes"), after the mode bits, each run written as there: {variable, high bit, low bit}.
constexpr std::array<ModeInfo, kModeCount> makeModes() {
  return {{
      {1, 0x00, 2, 2, true, 10, {5, 5, 5}, 20, {{{G2, 4, 4}, {B2, 4, 4}, {B3, 4, 4}, {R0, 9, 0},
                                                 {G0, 9, 0}, {B0, 9, 0}, {R1, 4, 0}, {G3, 4, 4},
                                                 {G2, 3, 0}, {G1, 4, 0}, {B3, 0, 0}, {G3, 3, 0},
                                                 {B1, 4, 0}, {B3, 1, 1}, {B2, 3, 0}, {R2, 4, 0},
                                                 {B3, 2, 2}, {R3, 4, 0}, {B3, 3, 3}, {P, 4, 0}}}},
      {2, 0x01, 2, 2, true, 7, {6, 6, 6}, 24, {{{G2, 5, 5}, {G3, 4, 4}, {G3, 5, 5}, {R0, 6, 0},
                                                {B3, 0, 0}, {B3, 1, 1}, {B2, 4, 4}, {G0, 6, 0},
                                                {B2, 5, 5}, {B3, 2, 2}, {G2, 4, 4}, {B0, 6, 0},
                                                {B3, 3, 3}, {B3, 5, 5}, {B3, 4, 4}, {R1, 5, 0},
                                                {G2, 3, 0}, {G1, 5, 0}, {G3, 3, 0}, {B1, 5, 0},
                                                {B2, 3, 0}, {R2, 5, 0}, {R3, 5, 0}, {P, 4, 0}}}},
      {3,
       0x02,
       5,
       2,
       true,
       11,
       {5, 4, 4},
       19,
       {{{R0, 9, 0},
         {G0, 9, 0},
         {B0, 9, 0},
         {R1, 4, 0},
         {R0, 10, 10},
         {G2, 3, 0},
         {G1, 3, 0},
         {G0, 10, 10},
         {B3, 0, 0},
         {G3, 3, 0},
         {B1, 3, 0},
         {B0, 10, 10},
         {B3, 1, 1},
         {B2, 3, 0},
         {R2, 4, 0},
         {B3, 2, 2},
         {R3, 4, 0},
         {B3, 3, 3},
         {P, 4, 0}}}},
      {4, 0x06, 5, 2, true, 11, {4, 5, 4}, 21, {{{R0, 9, 0},   {G0, 9, 0}, {B0, 9, 0}, {R1, 3, 0},
                                                 {R0, 10, 10}, {G3, 4, 4}, {G2, 3, 0}, {G1, 4, 0},
                                                 {G0, 10, 10}, {G3, 3, 0}, {B1, 3, 0}, {B0, 10, 10},
                                                 {B3, 1, 1},   {B2, 3, 0}, {R2, 3, 0}, {B3, 0, 0},
                                                 {B3, 2, 2},   {R3, 3, 0}, {G2, 4, 4}, {B3, 3, 3},
                                                 {P, 4, 0}}}},
      {5, 0x0A, 5, 2, true, 11, {4, 4, 5}, 21, {{{R0, 9, 0},   {G0, 9, 0}, {B0, 9, 0}, {R1, 3, 0},
                                                 {R0, 10, 10}, {B2, 4, 4}, {G2, 3, 0}, {G1, 3, 0},
                                                 {G0, 10, 10}, {B3, 0, 0}, {G3, 3, 0}, {B1, 4, 0},
                                                 {B0, 10, 10}, {B2, 3, 0}, {R2, 3, 0}, {B3, 1, 1},
                                                 {B3, 2, 2},   {R3, 3, 0}, {B3, 4, 4}, {B3, 3, 3},
                                                 {P, 4, 0}}}},
      {6, 0x0E, 5, 2, true, 9, {5, 5, 5}, 20, {{{R0, 8, 0}, {B2, 4, 4}, {G0, 8, 0}, {G2, 4, 4},
                                                {B0, 8, 0}, {B3, 4, 4}, {R1, 4, 0}, {G3, 4, 4},
                                                {G2, 3, 0}, {G1, 4, 0}, {B3, 0, 0}, {G3, 3, 0},
                                                {B1, 4, 0}, {B3, 1, 1}, {B2, 3, 0}, {R2, 4, 0},
                                                {B3, 2, 2}, {R3, 4, 0}, {B3, 3, 3}, {P, 4, 0}}}},
      {7, 0x12, 5, 2, true, 8, {6, 5, 5}, 20, {{{R0, 7, 0}, {G3, 4, 4}, {B2, 4, 4}, {G0, 7, 0},
                                                {B3, 2, 2}, {G2, 4, 4}, {B0, 7, 0}, {B3, 3, 3},
                                                {B3, 4, 4}, {R1, 5, 0}, {G2, 3, 0}, {G1, 4, 0},
                                                {B3, 0, 0}, {G3, 3, 0}, {B1, 4, 0}, {B3, 1, 1},
                                                {B2, 3, 0}, {R2, 5, 0}, {R3, 5, 0}, {P, 4, 0}}}},
      {8, 0x16, 5, 2, true, 8, {5, 6, 5}, 22, {{{R0, 7, 0}, {B3, 0, 0}, {B2, 4, 4}, {G0, 7, 0},
                                                {G2, 5, 5}, {G2, 4, 4}, {B0, 7, 0}, {G3, 5, 5},
                                                {B3, 4, 4}, {R1, 4, 0}, {G3, 4, 4}, {G2, 3, 0},
                                                {G1, 5, 0}, {G3, 3, 0}, {B1, 4, 0}, {B3, 1, 1},
                                                {B2, 3, 0}, {R2, 4, 0}, {B3, 2, 2}, {R3, 4, 0},
                                                {B3, 3, 3}, {P, 4, 0}}}},
      {9, 0x1A, 5, 2, true, 8, {5, 5, 6}, 22, {{{R0, 7, 0}, {B3, 1, 1}, {B2, 4, 4}, {G0, 7, 0},
                                                {B2, 5, 5}, {G2, 4, 4}, {B0, 7, 0}, {B3, 5, 5},
                                                {B3, 4, 4}, {R1, 4, 0}, {G3, 4, 4}, {G2, 3, 0},
                                                {G1, 4, 0}, {B3, 0, 0}, {G3, 3, 0}, {B1, 5, 0},
                                                {B2, 3, 0}, {R2, 4, 0}, {B3, 2, 2}, {R3, 4, 0},
                                                {B3, 3, 3}, {P, 4, 0}}}},
      {10, 0x1E, 5, 2, false, 6, {6, 6, 6}, 24, {{{R0, 5, 0}, {G3, 4, 4}, {B3, 0, 0}, {B3, 1, 1},
                                                  {B2, 4, 4}, {G0, 5, 0}, {G2, 5, 5}, {B2, 5, 5},
                                                  {B3, 2, 2}, {G2, 4, 4}, {B0, 5, 0}, {G3, 5, 5},
                                                  {B3, 3, 3}, {B3, 5, 5}, {B3, 4, 4}, {R1, 5, 0},
                                                  {G2, 3, 0}, {G1, 5, 0}, {G3, 3, 0}, {B1, 5, 0},
                                                  {B2, 3, 0}, {R2, 5, 0}, {R3, 5, 0}, {P, 4, 0}}}},
      {11,
       0x03,
       5,
       1,
       false,
       10,
       {10, 10, 10},
       6,
       {{{R0, 9, 0}, {G0, 9, 0}, {B0, 9, 0}, {R1, 9, 0}, {G1, 9, 0}, {B1, 9, 0}}}},
      {12,
       0x07,
       5,
       1,
       true,
       11,
       {9, 9, 9},
       9,
       {{{R0, 9, 0},
         {G0, 9, 0},
         {B0, 9, 0},
         {R1, 8, 0},
         {R0, 10, 10},
         {G1, 8, 0},
         {G0, 10, 10},
         {B1, 8, 0},
         {B0, 10, 10}}}},
      {13,
       0x0B,
       5,
       1,
       true,
       12,
       {8, 8, 8},
       9,
       {{{R0, 9, 0},
         {G0, 9, 0},
         {B0, 9, 0},
         {R1, 7, 0},
         {R0, 10, 11},
         {G1, 7, 0},
         {G0, 10, 11},
         {B1, 7, 0},
         {B0, 10, 11}}}},
      {14,
       0x0F,
       5,
       1,
       true,
       16,
       {4, 4, 4},
       9,
       {{{R0, 9, 0},
         {G0, 9, 0},
         {B0, 9, 0},
         {R1, 3, 0},
         {R0, 10, 15},
         {G1, 3, 0},
         {G0, 10, 15},
         {B1, 3, 0},
         {B0, 10, 15}}}},
  }};
}

// Every mode's fields fill the block up to its indices, and set each stored bit of each
// endpoint variable exactly once: a transcription error in the table above fails to compile.
constexpr bool layoutIsComplete(const ModeInfo& mode) {
  std::array<uint32_t, 13> seen{};
  int bits = mode.code_bits;
  for (int f = 0; f < mode.field_count; ++f) {
    const Field& field = mode.fields[f];
    const int step = field.from >= field.to ? 1 : -1;
    for (int i = 0, bit = field.to; i < field.count(); ++i, bit += step) {
      if (seen[field.var] & (1u << bit)) return false;
      seen[field.var] |= 1u << bit;
    }
    bits += field.count();
  }
  if (bits != indexStart(mode.regions)) return false;
  for (int var = 0; var < 3 * 2 * mode.regions; ++var) {
    const int width = var < 3 || !mode.transformed ? mode.endpoint_bits : mode.delta_bits[var % 3];
    if (seen[var] != (width >= 32 ? ~0u : (1u << width) - 1)) return false;
  }
  return seen[kPartitionBits] == (mode.regions == 2 ? 0x1Fu : 0u);
}

constexpr bool allLayoutsComplete(const std::array<ModeInfo, kModeCount>& modes) {
  for (const ModeInfo& mode : modes)
    if (!layoutIsComplete(mode)) return false;
  return true;
}
static_assert(allLayoutsComplete(makeModes()));

// The first 32 partitions of the BPTC 2-subset table: bit t is the subset of texel t.
constexpr std::array<uint16_t, kPartitionCount> kPartitions = {
    0xCCCC, 0x8888, 0xEEEE, 0xECC8, 0xC880, 0xFEEC, 0xFEC8, 0xEC80, 0xC800, 0xFFEC, 0xFE80,
    0xE800, 0xFFE8, 0xFF00, 0xFFF0, 0xF000, 0xF710, 0x008E, 0x7100, 0x08CE, 0x008C, 0x7310,
    0x3100, 0x8CCE, 0x088C, 0x3110, 0x6666, 0x366C, 0x17E8, 0x0FF0, 0x718E, 0x399C};
// The BPTC anchor index of the second subset of 2-subset partitions 0..31.
constexpr std::array<uint8_t, kPartitionCount> kAnchors = {
    15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15,
    15, 2,  8,  2,  2,  8,  8,  15, 2,  8,  2,  2,  8,  8,  2,  2};

constexpr bool anchorsInSubsetOne() {
  for (int p = 0; p < kPartitionCount; ++p)
    if (!((kPartitions[p] >> kAnchors[p]) & 1) || (kPartitions[p] & 1)) return false;
  return true;
}
static_assert(anchorsInSubsetOne());

int signExtend(int value, int bits) {
  const int sign = 1 << (bits - 1);
  return (value & (sign - 1)) - (value & sign);
}

}  // namespace

const std::array<ModeInfo, kModeCount> kModes = makeModes();

int modeIndexOf(const Bc6hBlock& block) {
  const uint32_t two = block[0] & 0x3;
  if (two < 2) return int(two);  // modes 1 and 2
  const uint32_t five = block[0] & 0x1F;
  for (int m = 2; m < kModeCount; ++m)
    if (kModes[m].code == five) return m;
  return -1;
}

int subsetOf(int partition, int texel) {
  return (kPartitions[partition] >> texel) & 1;
}
int anchorOf(int partition) {
  return kAnchors[partition];
}

uint32_t readBits(const Bc6hBlock& block, int start, int count) {
  uint32_t value = 0;
  for (int i = 0; i < count; ++i) {
    const int bit = start + i;
    value |= uint32_t((block[bit >> 3] >> (bit & 7)) & 1) << i;
  }
  return value;
}

void writeBits(Bc6hBlock& block, int start, int count, uint32_t value) {
  for (int i = 0; i < count; ++i) {
    const int bit = start + i;
    const uint8_t mask = uint8_t(1u << (bit & 7));
    if ((value >> i) & 1)
      block[bit >> 3] |= mask;
    else
      block[bit >> 3] &= uint8_t(~mask);
  }
}

void readEndpoints(const Bc6hBlock& block, const ModeInfo& mode, EndpointValues& stored,
                   int& partition) {
  stored = {};
  partition = 0;
  int pos = mode.code_bits;
  for (int f = 0; f < mode.field_count; ++f) {
    const Field& field = mode.fields[f];
    const int step = field.from >= field.to ? 1 : -1;
    for (int i = 0, bit = field.to; i < field.count(); ++i, bit += step) {
      const int value = int(readBits(block, pos++, 1)) << bit;
      if (field.var == kPartitionBits)
        partition |= value;
      else
        stored[field.var / 3][field.var % 3] |= value;
    }
  }
}

void writeEndpoints(Bc6hBlock& block, const ModeInfo& mode, const EndpointValues& stored,
                    int partition) {
  writeBits(block, 0, mode.code_bits, mode.code);
  int pos = mode.code_bits;
  for (int f = 0; f < mode.field_count; ++f) {
    const Field& field = mode.fields[f];
    const int step = field.from >= field.to ? 1 : -1;
    for (int i = 0, bit = field.to; i < field.count(); ++i, bit += step) {
      const int source =
          field.var == kPartitionBits ? partition : stored[field.var / 3][field.var % 3];
      writeBits(block, pos++, 1, uint32_t(source >> bit) & 1);
    }
  }
}

EndpointValues untransform(const ModeInfo& mode, const EndpointValues& stored) {
  if (!mode.transformed) return stored;
  EndpointValues values = stored;
  const int mask = (1 << mode.endpoint_bits) - 1;
  for (int e = 1; e < 2 * mode.regions; ++e)
    for (int c = 0; c < 3; ++c)
      values[e][c] = (stored[0][c] + signExtend(stored[e][c], mode.delta_bits[c])) & mask;
  return values;
}

}  // namespace rdm::bc6h
