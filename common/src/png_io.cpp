#include "rdm/png_io.h"

#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>

#include "rdm/check.h"

namespace rdm {
namespace {

constexpr uint8_t kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
constexpr size_t kMaxChunkData = size_t(1) << 30;  // PNG allows up to 2^31 - 1

void putU32(std::vector<uint8_t>& out, uint32_t v) {
  for (int shift = 24; shift >= 0; shift -= 8) out.push_back(uint8_t(v >> shift));
}

void appendChunk(std::vector<uint8_t>& out, const char* type, const uint8_t* data, size_t size) {
  RDM_CHECK(size <= kMaxChunkData);
  putU32(out, uint32_t(size));
  size_t start = out.size();
  out.insert(out.end(), type, type + 4);
  out.insert(out.end(), data, data + size);
  uLong crc = crc32(0L, Z_NULL, 0);
  crc = crc32(crc, out.data() + start, uInt(out.size() - start));
  putU32(out, uint32_t(crc));
}

// Scanlines with filter type 0 (None) before each row, zlib-compressed.
Status compressScanlines(int width, int height, int channels, const std::vector<uint8_t>& pixels,
                         std::vector<uint8_t>& compressed) {
  size_t row_bytes = size_t(width) * channels;
  std::vector<uint8_t> raw;
  raw.reserve((row_bytes + 1) * height);
  for (int y = 0; y < height; ++y) {
    raw.push_back(0);
    raw.insert(raw.end(), pixels.begin() + y * row_bytes, pixels.begin() + (y + 1) * row_bytes);
  }
  uLongf size = compressBound(uLong(raw.size()));
  compressed.resize(size);
  int rc = compress2(compressed.data(), &size, raw.data(), uLong(raw.size()), 6);
  if (rc != Z_OK) return Status::error("zlib compress2 failed with code " + std::to_string(rc));
  compressed.resize(size);
  return {};
}

std::vector<uint8_t> ihdr(int width, int height, int channels) {
  std::vector<uint8_t> data;
  putU32(data, uint32_t(width));
  putU32(data, uint32_t(height));
  uint8_t color_type = channels == 4 ? 6 : 2;  // RGBA : RGB
  for (uint8_t b : {uint8_t(8), color_type, uint8_t(0), uint8_t(0), uint8_t(0)}) data.push_back(b);
  return data;
}

Status writeFileAtomically(const std::string& path, const std::vector<uint8_t>& bytes) {
  static std::atomic<unsigned> counter{0};
  std::string tmp = path + ".tmp." + std::to_string(getpid()) + "." + std::to_string(counter++);
  std::FILE* file = std::fopen(tmp.c_str(), "wb");
  if (!file) return Status::error("cannot create '" + path + "': " + std::strerror(errno));
  bool ok = std::fwrite(bytes.data(), 1, bytes.size(), file) == bytes.size();
  int write_errno = errno;
  if (std::fclose(file) != 0 && ok) {
    ok = false;
    write_errno = errno;
  }
  if (!ok) {
    std::remove(tmp.c_str());
    return Status::error("cannot write '" + path + "': " + std::strerror(write_errno));
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    int rename_errno = errno;
    std::remove(tmp.c_str());
    return Status::error("cannot replace '" + path + "': " + std::strerror(rename_errno));
  }
  return {};
}

}  // namespace

Status writePng(const std::string& path, int width, int height, int channels,
                const std::vector<uint8_t>& pixels) {
  RDM_CHECK(channels == 3 || channels == 4);
  RDM_CHECK(width > 0 && height > 0);
  RDM_CHECK(pixels.size() == size_t(width) * height * channels);
  std::vector<uint8_t> compressed;
  Status status = compressScanlines(width, height, channels, pixels, compressed);
  if (!status) return Status::error("cannot encode PNG '" + path + "': " + status.message());
  std::vector<uint8_t> bytes(std::begin(kSignature), std::end(kSignature));
  std::vector<uint8_t> header = ihdr(width, height, channels);
  appendChunk(bytes, "IHDR", header.data(), header.size());
  for (size_t at = 0; at < compressed.size(); at += kMaxChunkData)
    appendChunk(bytes, "IDAT", compressed.data() + at,
                std::min(kMaxChunkData, compressed.size() - at));
  appendChunk(bytes, "IEND", nullptr, 0);
  return writeFileAtomically(path, bytes);
}

}  // namespace rdm
