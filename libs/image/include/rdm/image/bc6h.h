// BC6H unsigned float (VK_FORMAT_BC6H_UFLOAT_BLOCK, DXGI_FORMAT_BC6H_UF16) on the CPU: a decoder
// for all 14 modes and an encoder, per the Khronos Data Format Specification's BPTC chapter and
// Microsoft's "BC6H Format" page.
//
// Mode numbers are Microsoft's 1..14; Khronos names a mode by its mode-bit value instead:
// modes 1..10 (two regions) are Khronos 0, 1, 2, 6, 10, 14, 18, 22, 26, 30 and modes 11..14
// (one region) are Khronos 3, 7, 11, 15.
//
// A block holds 4 x 4 texels; texel i of a block is (i % 4, i / 4), x right and y down.
//
// Input contract of the encoder (per channel, in this order): NaN and values <= 0 (negative
// zero and negative infinity included) become 0, since BC6H_UFLOAT stores no sign and radiance
// is never negative; values above 65504 (half's largest finite value; +infinity included)
// become 65504; the rest are rounded to the nearest half before encoding. So an encoded block
// never decodes above 65504, and callers with brighter radiance scale it first (the atlas's
// per-tile exponent, docs/spec.md section 4).
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "rdm/base/status.h"
#include "rdm/image/image.h"

namespace rdm {

constexpr int kBc6hBlockBytes = 16;
constexpr int kBc6hBlockSide = 4;
constexpr float kBc6hMaxValue = 65504.0f;

using Bc6hBlock = std::array<uint8_t, kBc6hBlockBytes>;   // 128 bits, little-endian
using Bc6hTexels = std::array<std::array<float, 3>, 16>;  // RGB of texel x + 4 y

// Which modes the encoder tries. Every set keeps the block with the lowest squared error in
// half-bit space among the modes it tries.
enum class Bc6hModeSet {
  kMode11,     // one region, 10-bit endpoints only
  kOneRegion,  // modes 11..14: one region, 10..16-bit endpoints
  kAll,        // modes 11..14, plus modes 1..10 on the two partitions that fit best
};

struct Bc6hOptions {
  Bc6hModeSet modes = Bc6hModeSet::kAll;
  int threads = 1;  // worker threads (rdm::parallelFor); 0: one per hardware thread
};

// The block's mode, 1..14; 0 for the reserved mode values (which decode to black).
int bc6hBlockMode(const Bc6hBlock& block);

// Decodes every texel bit-exactly per the specification, as float RGB in [0, 65504].
Bc6hTexels decodeBc6hBlock(const Bc6hBlock& block);

// Encodes one block under the input contract above with shaders/shared/rdm_bc6h_encode.h, in
// 32-bit integer arithmetic: the same texels and modes give the same bytes on every machine,
// thread count and device (the Vulkan encoder runs the same code).
Bc6hBlock encodeBc6hBlock(const Bc6hTexels& texels, Bc6hModeSet modes = Bc6hModeSet::kAll);

// The input contract applied to one value: what the encoder stores before rounding to half.
float bc6hClampInput(float value);

// A BC6H image: blocks in row-major block order, 16 bytes each, ceil(width/4) per block row.
struct Bc6hImage {
  int width = 0;
  int height = 0;
  std::vector<uint8_t> blocks;
  int blocksWide() const { return (width + 3) / 4; }
  int blocksHigh() const { return (height + 3) / 4; }
};

// Ok when `image` can be encoded: kInvalidInput naming "width" or "height" unless both are
// positive multiples of 4, and "channels" when it has fewer than 3 channels.
[[nodiscard]] Status bc6hCheckEncodable(const Image& image);

// Encodes channels 0..2 of `image` (R, G, B; further channels such as Z are ignored); fails as
// bc6hCheckEncodable. The Vulkan encoder (rdm/vulkan/vulkan_bc6h.h) gives the same blocks.
Expected<Bc6hImage> encodeBc6h(const Image& image, const Bc6hOptions& options = {});

// An encoder a writer is given (rdm::encodeBc6h's contract): the CPU's, or a device's such
// as rdm::VulkanBc6hEncoder::encode. Empty: encodeBc6h on every core.
using Bc6hEncodeFn = std::function<Expected<Bc6hImage>(const Image&)>;

// The 3-channel float image of `bc6h`. Fails (naming "blocks", "width" or "height") when the
// block count does not match the size.
Expected<Image> decodeBc6h(const Bc6hImage& bc6h);

}  // namespace rdm
