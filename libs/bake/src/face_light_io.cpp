// face_light.bin (docs/spec.md section 4.6) and its RGB9E5 light values.
#include <algorithm>
#include <cmath>
#include <cstring>

#include "rdm/bake/face_light.h"
#include "rdm/base/binary_io.h"
#include "rdm/base/file_util.h"
#include "rdm/base/hash.h"

namespace rdm {
namespace {

constexpr char kMagic[8] = {'R', 'D', 'M', 'F', 'A', 'C', 'E', 'L'};
// 3: a trailing XXH3 64 of every byte before it. 2: no checksum (still read, unverified).
// 1: the digest included the bake settings and cameras (refused).
constexpr uint32_t kVersion = 3;
constexpr uint32_t kUncheckedVersion = 2;
constexpr int kMantissaBits = 9, kExponentBias = 15;
constexpr float kMaxRgb9e5 = 65408.0f;  // (511 / 512) * 2^16
constexpr uint64_t kMaxFacesPerSlot = uint64_t(shared::kBlockVoxelCount) * shared::kFaceCount;

float clampComponent(float c) {
  return c > 0.0f ? std::min(c, kMaxRgb9e5) : 0.0f;  // NaN compares false: 0
}

bool slotBefore(const glm::ivec3& a, const glm::ivec3& b) {
  if (a.x != b.x) return a.x < b.x;
  if (a.y != b.y) return a.y < b.y;
  return a.z < b.z;
}

Status malformed(const std::string& path, const std::string& what) {
  return Status::error(StatusCode::kMalformed, path + ": " + what);
}

Status checkSlot(const std::string& path, const FaceLightSlot& s, const FaceLightSlot* previous) {
  const std::string where = "slot (" + std::to_string(s.slot.x) + ", " + std::to_string(s.slot.y) +
                            ", " + std::to_string(s.slot.z) + ")";
  if (glm::any(glm::lessThan(s.slot, glm::ivec3(0))) ||
      glm::any(glm::greaterThan(s.slot, glm::ivec3(255))))
    return malformed(path, where + " is outside 0..255");
  if (previous && !slotBefore(previous->slot, s.slot))
    return malformed(path, where + " is not after the slot before it ((i, j, k) order)");
  for (size_t i = 0; i < s.faces.size(); ++i) {
    if (s.faces[i] >= kMaxFacesPerSlot || (i > 0 && s.faces[i] <= s.faces[i - 1]))
      return malformed(path, where + ": face " + std::to_string(i) + " is out of range or order");
  }
  return {};
}

}  // namespace

uint32_t encodeRgb9e5(const glm::vec3& rgb) {
  const float r = clampComponent(rgb.r), g = clampComponent(rgb.g), b = clampComponent(rgb.b);
  const float max_c = std::max(r, std::max(g, b));
  int exponent = 0;  // floor(log2(max_c)) + 1 + bias, at least 0
  if (max_c > 0.0f) {
    int e2 = 0;
    std::frexp(max_c, &e2);  // max_c = f 2^e2, f in [0.5, 1)
    exponent = std::max(-kExponentBias - 1, e2 - 1) + 1 + kExponentBias;
  }
  auto scaled = [&](float c, int e) {
    return uint32_t(std::floor(std::ldexp(c, kExponentBias + kMantissaBits - e) + 0.5f));
  };
  if (scaled(max_c, exponent) == (1u << kMantissaBits)) ++exponent;
  return scaled(r, exponent) | scaled(g, exponent) << 9 | scaled(b, exponent) << 18 |
         uint32_t(exponent) << 27;
}

Status writeFaceLight(const std::string& path, const FaceLight& light) {
  BinaryWriter w;
  w.bytes().append(kMagic, sizeof(kMagic));
  w.put(kVersion);
  w.put(light.spp);
  w.putString(light.scene_digest);
  w.put(uint64_t(light.slots.size()));
  for (const FaceLightSlot& s : light.slots) {
    RDM_CHECK(s.faces.size() == s.light.size());
    w.put(s.slot);
    w.putArray(s.faces);
    std::vector<uint32_t> packed(s.light.size());
    std::transform(s.light.begin(), s.light.end(), packed.begin(), encodeRgb9e5);
    w.bytes().append(reinterpret_cast<const char*>(packed.data()),
                     packed.size() * sizeof(uint32_t));
  }
  w.put(contentHash(w.bytes()));
  return writeFileAtomic(path, w.bytes());
}

Expected<FaceLight> readFaceLight(const std::string& path) {
  auto bytes = readFileToString(path);
  if (!bytes) return bytes.status();
  return decodeFaceLight(*bytes, path);
}

Expected<FaceLight> decodeFaceLight(const std::string& bytes, const std::string& path) {
  if (bytes.size() < sizeof(kMagic) || std::memcmp(bytes.data(), kMagic, sizeof(kMagic)) != 0)
    return malformed(path, "not a face light file (no RDMFACEL magic)");
  uint32_t version = 0;
  if (bytes.size() < sizeof(kMagic) + sizeof(version))
    return Status::error(StatusCode::kCorrupt, path + ": truncated header");
  std::memcpy(&version, bytes.data() + sizeof(kMagic), sizeof(version));
  if (version != kVersion && version != kUncheckedVersion)
    return malformed(path, "face light version " + std::to_string(version) + ", this build reads " +
                               std::to_string(kUncheckedVersion) + " and " +
                               std::to_string(kVersion) + ": bake again");
  size_t end = bytes.size();
  if (version == kVersion) {
    uint64_t stored = 0;
    if (end < sizeof(kMagic) + sizeof(version) + sizeof(stored))
      return Status::error(StatusCode::kCorrupt, path + ": cut short before its checksum");
    end -= sizeof(stored);
    std::memcpy(&stored, bytes.data() + end, sizeof(stored));
    if (contentHash(std::string_view(bytes.data(), end)) != stored)
      return Status::error(StatusCode::kCorrupt,
                           path + ": fails its checksum (the file is damaged or cut short)");
  }
  const std::string body =
      bytes.substr(sizeof(kMagic) + sizeof(version), end - sizeof(kMagic) - sizeof(version));
  BinaryReader r(body);
  FaceLight light;
  uint64_t slot_count = 0;
  if (!r.get(light.spp) || !r.getString(light.scene_digest, 256) || !r.get(slot_count) ||
      slot_count > uint64_t(256) * 256 * 256)
    return malformed(path, "truncated or corrupt header");
  for (uint64_t i = 0; i < slot_count; ++i) {
    FaceLightSlot s;
    std::vector<uint32_t> packed;
    if (!r.get(s.slot) || !r.getArray(s.faces, kMaxFacesPerSlot))
      return malformed(path, "truncated at slot " + std::to_string(i));
    packed.resize(s.faces.size());
    for (uint32_t& word : packed)
      if (!r.get(word)) return malformed(path, "truncated at slot " + std::to_string(i));
    if (Status st = checkSlot(path, s, light.slots.empty() ? nullptr : &light.slots.back()); !st)
      return st;
    s.light.resize(packed.size());
    std::transform(packed.begin(), packed.end(), s.light.begin(), shared::decodeRgb9e5);
    light.slots.push_back(std::move(s));
  }
  if (!r.atEnd()) return malformed(path, "trailing bytes after the last slot");
  return light;
}

}  // namespace rdm
