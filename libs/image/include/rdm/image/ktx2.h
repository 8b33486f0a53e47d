// A minimal KTX 2.0 container (Khronos KTX File Format Specification 2.0) for one 2D image with
// one mip level, one layer and one face, no supercompression and no key/value data, in
// VK_FORMAT_BC6H_UFLOAT_BLOCK or VK_FORMAT_R16G16B16A16_SFLOAT. Files carry the basic Data
// Format Descriptor the specification requires (model BC6H or RGBSDA, BT.709 primaries, linear
// transfer). Multi-byte fields are little-endian.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "rdm/base/status.h"

namespace rdm {

// The Vulkan format numbers a KTX2 file names in vkFormat.
enum class Ktx2Format : uint32_t {
  kRgba16Sfloat = 97,  // VK_FORMAT_R16G16B16A16_SFLOAT: 8 bytes per texel, R G B A halves
  kBc6hUfloat = 143,   // VK_FORMAT_BC6H_UFLOAT_BLOCK: 16 bytes per 4 x 4 block (bc6h.h)
};

// Largest side a reader accepts: the largest atlas page (docs/spec.md section 4).
constexpr uint32_t kKtx2MaxSide = 16384;

struct Ktx2Image {
  Ktx2Format format = Ktx2Format::kBc6hUfloat;
  int width = 0, height = 0;
  std::vector<uint8_t> data;  // level 0: ktx2LevelBytes(format, width, height) bytes
};

// Bytes of level 0: ceil(w/4) * ceil(h/4) * 16 for BC6H, w * h * 8 for RGBA16F.
uint64_t ktx2LevelBytes(Ktx2Format format, int width, int height);

// The file's bytes. Requires 1 <= width, height <= kKtx2MaxSide and data of
// ktx2LevelBytes(...) bytes (RDM_CHECK).
std::string encodeKtx2(const Ktx2Image& image);

// Writes encodeKtx2(image) to `path` atomically (writeFileAtomic: temp file, fsync, rename).
[[nodiscard]] Status writeKtx2(const std::string& path, const Ktx2Image& image);

// Parses and validates a file's bytes: the identifier, every header field this writer sets
// (vkFormat, typeSize, pixelWidth, pixelHeight, pixelDepth, layerCount, faceCount, levelCount,
// supercompressionScheme), the index's ranges, the descriptor and the level's offset, alignment
// and length. An error names the field in Status::field() and the message; a file cut short is
// kCorrupt, a field with a value outside what this reader handles kInvalidInput.
[[nodiscard]] Expected<Ktx2Image> decodeKtx2(const std::string& bytes);

// readFileToString + decodeKtx2; errors name `path`.
[[nodiscard]] Expected<Ktx2Image> readKtx2(const std::string& path);

}  // namespace rdm
