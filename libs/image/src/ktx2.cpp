#include "rdm/image/ktx2.h"

#include <array>
#include <cstring>
#include <utility>

#include "rdm/base/check.h"
#include "rdm/base/file_util.h"

namespace rdm {
namespace {

constexpr std::array<uint8_t, 12> kIdentifier = {0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32,
                                                 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A};
constexpr size_t kHeaderBytes = 80;  // identifier, header and index
constexpr size_t kLevelIndexBytes = 24;
constexpr size_t kDfdOffset = kHeaderBytes + kLevelIndexBytes;

// Data Format Descriptor values (Khronos Data Format Specification, khr_df.h).
constexpr uint32_t kDfVersion = 2;
constexpr uint32_t kModelRgbsda = 1, kModelBc6h = 133;
constexpr uint32_t kPrimariesBt709 = 1, kTransferLinear = 1;
constexpr uint32_t kQualifierFloat = 0x80, kQualifierSigned = 0x40;
constexpr uint32_t kFloatMinusOne = 0xBF800000, kFloatZero = 0, kFloatOne = 0x3F800000;

struct Sample {
  uint32_t bit_offset, bit_length, channel;
};

struct FormatTraits {
  uint32_t type_size, model, block_side, block_bytes;
  bool is_signed;
  std::vector<Sample> samples;
};

FormatTraits traitsOf(Ktx2Format format) {
  if (format == Ktx2Format::kBc6hUfloat) return {1, kModelBc6h, 4, 16, false, {{0, 128, 0}}};
  return {2, kModelRgbsda, 1, 8, true, {{0, 16, 0}, {16, 16, 1}, {32, 16, 2}, {48, 16, 15}}};
}

bool knownFormat(uint32_t vk_format) {
  return vk_format == uint32_t(Ktx2Format::kBc6hUfloat) ||
         vk_format == uint32_t(Ktx2Format::kRgba16Sfloat);
}

uint64_t alignUp(uint64_t value, uint64_t alignment) {
  return (value + alignment - 1) / alignment * alignment;
}

// lcm(texel block size, 4), the level alignment the specification asks of unsupercompressed
// data: 16 for BC6H, 8 for RGBA16F.
uint64_t levelAlignment(Ktx2Format format) {
  return traitsOf(format).block_bytes;
}

void put32(std::string& out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(char((v >> (8 * i)) & 0xFF));
}
void put64(std::string& out, uint64_t v) {
  put32(out, uint32_t(v));
  put32(out, uint32_t(v >> 32));
}
uint32_t get32(const std::string& in, size_t at) {
  uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= uint32_t(uint8_t(in[at + i])) << (8 * i);
  return v;
}
uint64_t get64(const std::string& in, size_t at) {
  return uint64_t(get32(in, at)) | (uint64_t(get32(in, at + 4)) << 32);
}

std::string descriptor(Ktx2Format format) {
  const FormatTraits traits = traitsOf(format);
  const uint32_t block_size = 24 + 16 * uint32_t(traits.samples.size());
  std::string dfd;
  put32(dfd, 4 + block_size);                   // dfdTotalSize
  put32(dfd, 0);                                // vendorId KHR, descriptorType basic
  put32(dfd, kDfVersion | (block_size << 16));  // versionNumber, descriptorBlockSize
  put32(dfd, traits.model | (kPrimariesBt709 << 8) | (kTransferLinear << 16));  // flags 0
  const uint32_t dim = traits.block_side - 1;
  put32(dfd, dim | (dim << 8));    // texelBlockDimension0..3
  put32(dfd, traits.block_bytes);  // bytesPlane0..3
  put32(dfd, 0);                   // bytesPlane4..7
  const uint32_t qualifiers = kQualifierFloat | (traits.is_signed ? kQualifierSigned : 0);
  for (const Sample& s : traits.samples) {
    put32(dfd, s.bit_offset | ((s.bit_length - 1) << 16) | ((s.channel | qualifiers) << 24));
    put32(dfd, 0);                                               // samplePosition0..3
    put32(dfd, traits.is_signed ? kFloatMinusOne : kFloatZero);  // sampleLower
    put32(dfd, kFloatOne);                                       // sampleUpper
  }
  return dfd;
}

Status truncated(const std::string& field, const std::string& what) {
  return Status::error(StatusCode::kCorrupt, "field '" + field + "': " + what, field);
}

Status expectField(const std::string& field, uint64_t value, uint64_t wanted) {
  if (value == wanted) return {};
  return Status::invalidField(
      field, "is " + std::to_string(value) + ", expected " + std::to_string(wanted));
}

// A byte range [offset, offset + length) of a `size`-byte file.
Status checkRange(const std::string& field, uint64_t offset, uint64_t length, uint64_t size) {
  if (offset <= size && length <= size - offset) return {};
  return truncated(field, "range " + std::to_string(offset) + " + " + std::to_string(length) +
                              " passes the end of the " + std::to_string(size) + "-byte file");
}

Status checkHeader(const std::string& in, Ktx2Format& format) {
  if (in.size() < kHeaderBytes)
    return truncated("header", "the file has " + std::to_string(in.size()) +
                                   " bytes, fewer than the " + std::to_string(kHeaderBytes) +
                                   " of identifier, header and index");
  if (std::memcmp(in.data(), kIdentifier.data(), kIdentifier.size()) != 0)
    return Status::invalidField("identifier", "not the KTX 2.0 file identifier");
  const uint32_t vk_format = get32(in, 12);
  if (!knownFormat(vk_format))
    return Status::invalidField("vkFormat", std::to_string(vk_format) +
                                                " is neither BC6H_UFLOAT_BLOCK (143) nor "
                                                "R16G16B16A16_SFLOAT (97)");
  format = Ktx2Format(vk_format);
  for (const auto& [field, at] : {std::pair{"pixelWidth", 20}, {"pixelHeight", 24}})
    if (get32(in, at) == 0 || get32(in, at) > kKtx2MaxSide)
      return Status::invalidField(
          field, std::to_string(get32(in, at)) + " is outside 1.." + std::to_string(kKtx2MaxSide));
  const std::pair<const char*, std::pair<size_t, uint32_t>> fixed[] = {
      {"typeSize", {16, traitsOf(format).type_size}},
      {"pixelDepth", {28, 0}},
      {"layerCount", {32, 0}},
      {"faceCount", {36, 1}},
      {"levelCount", {40, 1}},
      {"supercompressionScheme", {44, 0}}};
  for (const auto& [field, spec] : fixed)
    if (Status s = expectField(field, get32(in, spec.first), spec.second); !s.ok()) return s;
  if (Status s = expectField("sgdByteLength", get64(in, 72), 0); !s.ok()) return s;
  return checkRange("kvdByteOffset", get32(in, 56), get32(in, 60), in.size());
}

// The descriptor's fields that say how to read the level: its size, colour model, texel block
// and bytes per block.
Status checkDescriptor(const std::string& in, Ktx2Format format) {
  const uint32_t offset = get32(in, 48), length = get32(in, 52);
  if (Status s = checkRange("dfdByteOffset", offset, length, in.size()); !s.ok()) return s;
  if (length < 28) return truncated("dfdByteLength", std::to_string(length) + " is too short");
  const FormatTraits traits = traitsOf(format);
  const uint32_t dim = traits.block_side - 1;
  if (Status s = expectField("dfdTotalSize", get32(in, offset), length); !s.ok()) return s;
  if (Status s = expectField("dfd.colorModel", get32(in, offset + 12) & 0xFF, traits.model);
      !s.ok())
    return s;
  if (Status s = expectField("dfd.texelBlockDimension", get32(in, offset + 16), dim | (dim << 8));
      !s.ok())
    return s;
  return expectField("dfd.bytesPlane0", get32(in, offset + 20) & 0xFF, traits.block_bytes);
}

Status checkLevel(const std::string& in, const Ktx2Image& image, uint64_t& offset) {
  if (in.size() < kDfdOffset)
    return truncated("levelIndex", "the file ends inside the level index");
  offset = get64(in, kHeaderBytes);
  const uint64_t length = get64(in, kHeaderBytes + 8);
  const uint64_t wanted = ktx2LevelBytes(image.format, image.width, image.height);
  if (Status s = expectField("levels[0].byteLength", length, wanted); !s.ok()) return s;
  if (Status s =
          expectField("levels[0].uncompressedByteLength", get64(in, kHeaderBytes + 16), wanted);
      !s.ok())
    return s;
  if (offset % levelAlignment(image.format) != 0)
    return Status::invalidField("levels[0].byteOffset",
                                std::to_string(offset) + " is not a multiple of " +
                                    std::to_string(levelAlignment(image.format)));
  return checkRange("levels[0].byteOffset", offset, length, in.size());
}

}  // namespace

uint64_t ktx2LevelBytes(Ktx2Format format, int width, int height) {
  const FormatTraits traits = traitsOf(format);
  const uint64_t wide = (uint64_t(width) + traits.block_side - 1) / traits.block_side;
  const uint64_t high = (uint64_t(height) + traits.block_side - 1) / traits.block_side;
  return wide * high * traits.block_bytes;
}

std::string encodeKtx2(const Ktx2Image& image) {
  RDM_CHECK(image.width >= 1 && image.height >= 1);
  RDM_CHECK(uint32_t(image.width) <= kKtx2MaxSide && uint32_t(image.height) <= kKtx2MaxSide);
  RDM_CHECK(image.data.size() == ktx2LevelBytes(image.format, image.width, image.height));
  const std::string dfd = descriptor(image.format);
  const uint64_t level_offset = alignUp(kDfdOffset + dfd.size(), levelAlignment(image.format));
  std::string out(kIdentifier.begin(), kIdentifier.end());
  for (uint32_t v : {uint32_t(image.format), traitsOf(image.format).type_size,
                     uint32_t(image.width), uint32_t(image.height), 0u, 0u, 1u, 1u, 0u})
    put32(out, v);  // vkFormat .. supercompressionScheme
  put32(out, uint32_t(kDfdOffset));
  put32(out, uint32_t(dfd.size()));
  put32(out, 0), put32(out, 0);  // no key/value data
  put64(out, 0), put64(out, 0);  // no supercompression global data
  put64(out, level_offset);
  put64(out, image.data.size());
  put64(out, image.data.size());
  out += dfd;
  out.resize(level_offset, '\0');
  out.append(reinterpret_cast<const char*>(image.data.data()), image.data.size());
  return out;
}

Status writeKtx2(const std::string& path, const Ktx2Image& image) {
  return writeFileAtomic(path, encodeKtx2(image));
}

Expected<Ktx2Image> decodeKtx2(const std::string& bytes) {
  Ktx2Image image;
  if (Status s = checkHeader(bytes, image.format); !s.ok()) return s;
  image.width = int(get32(bytes, 20));
  image.height = int(get32(bytes, 24));
  uint64_t offset = 0;
  if (Status s = checkLevel(bytes, image, offset); !s.ok()) return s;
  if (Status s = checkDescriptor(bytes, image.format); !s.ok()) return s;
  const auto* begin = reinterpret_cast<const uint8_t*>(bytes.data()) + offset;
  image.data.assign(begin, begin + ktx2LevelBytes(image.format, image.width, image.height));
  return image;
}

Expected<Ktx2Image> readKtx2(const std::string& path) {
  Expected<std::string> bytes = readFileToString(path);
  if (!bytes.ok()) return bytes.status();
  Expected<Ktx2Image> image = decodeKtx2(*bytes);
  if (image.ok()) return image;
  const Status& s = image.status();
  return Status::error(s.code(), path + ": " + s.message(), s.field());
}

}  // namespace rdm
