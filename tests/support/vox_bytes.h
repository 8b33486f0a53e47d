// MagicaVoxel .vox files built byte by byte for the import tests (little-endian chunks:
// id, content size, children size, content).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace rdm::test {

using VoxItems = std::vector<std::pair<std::string, std::string>>;

inline void put32(std::string& s, uint32_t v) {
  s.append(reinterpret_cast<const char*>(&v), 4);
}

inline std::string chunk(const std::string& id, const std::string& content) {
  std::string s = id;
  put32(s, uint32_t(content.size()));
  put32(s, 0);
  return s + content;
}

inline std::string str(const std::string& s) {
  std::string out;
  put32(out, uint32_t(s.size()));
  return out + s;
}

inline std::string dict(const VoxItems& items) {
  std::string out;
  put32(out, uint32_t(items.size()));
  for (const auto& [k, v] : items) out += str(k) + str(v);
  return out;
}

// SIZE and XYZI of one model; voxels are x, y, z, colour index.
inline std::string model(std::array<uint32_t, 3> size,
                         const std::vector<std::array<uint8_t, 4>>& voxels) {
  std::string s, xyzi;
  for (uint32_t v : size) put32(s, v);
  put32(xyzi, uint32_t(voxels.size()));
  for (const auto& v : voxels) xyzi.append(reinterpret_cast<const char*>(v.data()), 4);
  return chunk("SIZE", s) + chunk("XYZI", xyzi);
}

}  // namespace rdm::test
