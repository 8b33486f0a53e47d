// The decoder's view of shaders/shared/rdm_bc6h.h's tables (bc6h_format.h), checked at compile
// time against the block layout's invariants.
#include "bc6h_format.h"

namespace rdm::bc6h {
namespace {

// The mode table of shaders/shared/rdm_bc6h.h as ModeInfo.
constexpr std::array<ModeInfo, kModeCount> makeModes() {
  std::array<ModeInfo, kModeCount> modes{};
  for (int m = 0; m < kModeCount; ++m) {
    ModeInfo& mode = modes[size_t(m)];
    mode.number = m + 1;
    mode.code = uint8_t(shared::kBc6hModeCode[m]);
    mode.code_bits = shared::kBc6hModeCodeBits[m];
    mode.regions = shared::kBc6hModeRegions[m];
    mode.transformed = shared::kBc6hModeTransformed[m];
    mode.endpoint_bits = shared::kBc6hEndpointBits[m];
    for (int c = 0; c < 3; ++c) mode.delta_bits[size_t(c)] = shared::kBc6hDeltaBits[3 * m + c];
    mode.field_count = shared::kBc6hFieldStart[m + 1] - shared::kBc6hFieldStart[m];
    for (int f = 0; f < mode.field_count; ++f) {
      const uint32_t packed = shared::kBc6hFields[shared::kBc6hFieldStart[m] + f];
      mode.fields[size_t(f)] = {uint8_t(packed >> 8), uint8_t((packed >> 4) & 15),
                                uint8_t(packed & 15)};
    }
  }
  return modes;
}

// Every mode's fields fill the block up to its indices, and set each stored bit of each
// endpoint variable exactly once: a transcription error in rdm_bc6h.h fails to compile.
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

constexpr bool anchorsInSubsetOne() {
  for (int p = 0; p < kPartitionCount; ++p)
    if (!((shared::kBc6hPartitions[p] >> shared::kBc6hAnchors[p]) & 1) ||
        (shared::kBc6hPartitions[p] & 1))
      return false;
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
  return shared::bc6hSubset(2, partition, texel);
}
int anchorOf(int partition) {
  return shared::kBc6hAnchors[partition];
}

uint32_t readBits(const Bc6hBlock& block, int start, int count) {
  uint32_t value = 0;
  for (int i = 0; i < count; ++i) {
    const int bit = start + i;
    value |= uint32_t((block[bit >> 3] >> (bit & 7)) & 1) << i;
  }
  return value;
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
