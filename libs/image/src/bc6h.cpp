// The BC6H_UFLOAT decoder and the image-level encode and decode (bc6h.h); the block encoder is
// bc6h_encode.cpp and the format's tables bc6h_format.cpp.
#include "rdm/image/bc6h.h"

#include <Imath/half.h>

#include <cstring>
#include <string>

#include "bc6h_format.h"
#include "rdm/base/parallel.h"

namespace rdm {
namespace {

using namespace bc6h;

float halfBitsToFloat(int bits) {
  Imath::half h;
  h.setBits(uint16_t(bits));
  return float(h);
}

Bc6hTexels gatherBlock(const Image& image, int bx, int by) {
  Bc6hTexels texels{};
  for (int t = 0; t < 16; ++t) {
    const int x = bx * kBc6hBlockSide + t % 4, y = by * kBc6hBlockSide + t / 4;
    const float* pixel = &image.pixels[(size_t(y) * image.width + x) * image.channels];
    texels[t] = {pixel[0], pixel[1], pixel[2]};
  }
  return texels;
}

void scatterBlock(const Bc6hTexels& texels, int bx, int by, Image& image) {
  for (int t = 0; t < 16; ++t) {
    const int x = bx * kBc6hBlockSide + t % 4, y = by * kBc6hBlockSide + t / 4;
    if (x >= image.width || y >= image.height) continue;
    for (int c = 0; c < 3; ++c) image.at(x, y, c) = texels[t][c];
  }
}

}  // namespace

int bc6hBlockMode(const Bc6hBlock& block) {
  const int index = modeIndexOf(block);
  return index < 0 ? 0 : kModes[index].number;
}

Bc6hTexels decodeBc6hBlock(const Bc6hBlock& block) {
  Bc6hTexels texels{};
  const int mode_index = modeIndexOf(block);
  if (mode_index < 0) return texels;
  const ModeInfo& mode = kModes[mode_index];
  EndpointValues stored;
  int partition = 0;
  readEndpoints(block, mode, stored, partition);
  const EndpointValues values = untransform(mode, stored);
  std::array<std::array<int, 3>, 4> endpoints{};
  for (int e = 0; e < 2 * mode.regions; ++e)
    for (int c = 0; c < 3; ++c) endpoints[e][c] = unquantize(values[e][c], mode.endpoint_bits);
  const int bits = indexBits(mode.regions);
  int pos = indexStart(mode.regions);
  for (int t = 0; t < 16; ++t) {
    const int subset = mode.regions == 2 ? subsetOf(partition, t) : 0;
    const bool anchor = t == 0 || (mode.regions == 2 && t == anchorOf(partition));
    const int count = anchor ? bits - 1 : bits;
    const int weight = weightOf(mode.regions, int(readBits(block, pos, count)));
    pos += count;
    for (int c = 0; c < 3; ++c)
      texels[t][c] = halfBitsToFloat(
          interpolateToHalf(endpoints[2 * subset][c], endpoints[2 * subset + 1][c], weight));
  }
  return texels;
}

Status bc6hCheckEncodable(const Image& image) {
  if (image.width <= 0 || image.width % kBc6hBlockSide != 0)
    return Status::invalidField(
        "width", "must be a positive multiple of 4, not " + std::to_string(image.width));
  if (image.height <= 0 || image.height % kBc6hBlockSide != 0)
    return Status::invalidField(
        "height", "must be a positive multiple of 4, not " + std::to_string(image.height));
  if (image.channels < 3)
    return Status::invalidField(
        "channels", "BC6H needs R, G, B; the image has " + std::to_string(image.channels));
  return {};
}

Expected<Bc6hImage> encodeBc6h(const Image& image, const Bc6hOptions& options) {
  if (Status status = bc6hCheckEncodable(image); !status.ok()) return status;
  Bc6hImage out;
  out.width = image.width;
  out.height = image.height;
  const int wide = out.blocksWide(), high = out.blocksHigh();
  out.blocks.resize(size_t(wide) * size_t(high) * kBc6hBlockBytes);
  ParallelOptions parallel;
  parallel.threads = options.threads;
  parallelFor(size_t(high), parallel, [&](size_t by) {
    for (int bx = 0; bx < wide; ++bx) {
      const Bc6hBlock block = encodeBc6hBlock(gatherBlock(image, bx, int(by)), options.modes);
      std::memcpy(&out.blocks[(by * size_t(wide) + size_t(bx)) * kBc6hBlockBytes], block.data(),
                  kBc6hBlockBytes);
    }
    return true;
  });
  return out;
}

Expected<Image> decodeBc6h(const Bc6hImage& bc6h) {
  if (bc6h.width <= 0)
    return Status::invalidField("width", "must be positive, not " + std::to_string(bc6h.width));
  if (bc6h.height <= 0)
    return Status::invalidField("height", "must be positive, not " + std::to_string(bc6h.height));
  const int wide = bc6h.blocksWide(), high = bc6h.blocksHigh();
  const size_t expected = size_t(wide) * size_t(high) * kBc6hBlockBytes;
  if (bc6h.blocks.size() != expected)
    return Status::invalidField("blocks", std::to_string(bc6h.blocks.size()) + " bytes for a " +
                                              std::to_string(bc6h.width) + " x " +
                                              std::to_string(bc6h.height) + " image, not " +
                                              std::to_string(expected));
  Image image(bc6h.width, bc6h.height, 3);
  for (int by = 0; by < high; ++by)
    for (int bx = 0; bx < wide; ++bx) {
      Bc6hBlock block;
      std::memcpy(block.data(), &bc6h.blocks[(size_t(by) * wide + bx) * kBc6hBlockBytes],
                  kBc6hBlockBytes);
      scatterBlock(decodeBc6hBlock(block), bx, by, image);
    }
  return image;
}

}  // namespace rdm
