// The BC6H_UFLOAT block encoder (bc6h.h) on the CPU: shaders/shared/rdm_bc6h_encode.h, the
// encoder the Vulkan pass (shaders/bc6h_encode.comp) runs too, so both give the same blocks
// (docs/bc6h.md, "Encoder").
#include <algorithm>
#include <bit>
#include <cstdint>

#include "rdm/image/bc6h.h"
#include "shared/rdm_bc6h_encode.h"

namespace rdm {

static_assert(int(Bc6hModeSet::kMode11) == shared::kBc6hModesMode11 &&
              int(Bc6hModeSet::kOneRegion) == shared::kBc6hModesOneRegion &&
              int(Bc6hModeSet::kAll) == shared::kBc6hModesAll);

float bc6hClampInput(float value) {
  if (!(value > 0.0f)) return 0.0f;  // NaN, zeros and negatives
  return std::min(value, kBc6hMaxValue);
}

Bc6hBlock encodeBc6hBlock(const Bc6hTexels& texels, Bc6hModeSet modes) {
  shared::Bc6hSource source;
  source.count = 16;
  for (int t = 0; t < 16; ++t)
    for (int c = 0; c < 3; ++c)
      source.h[t][c] = shared::bc6hInputHalf(std::bit_cast<uint32_t>(texels[size_t(t)][size_t(c)]));
  const glm::uvec4 words = shared::bc6hEncodeBlock(source, int(modes));
  Bc6hBlock block;
  for (int b = 0; b < kBc6hBlockBytes; ++b)
    block[size_t(b)] = uint8_t(words[b / 4] >> (8 * (b % 4)));
  return block;
}

}  // namespace rdm
