#include "rdm/vox_import.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <map>

namespace rdm {
namespace {

constexpr int kMaxModelSize = 256 * 16;  // the grid's limit in voxels

struct Reader {
  const std::string& bytes;
  size_t pos = 0;
  bool has(size_t n) const { return pos + n <= bytes.size(); }
  uint32_t u32() {
    uint32_t v;
    std::memcpy(&v, bytes.data() + pos, 4);  // .vox is little-endian, as is every target here
    pos += 4;
    return v;
  }
  std::string id() {
    std::string s = bytes.substr(pos, 4);
    pos += 4;
    return s;
  }
};

struct VoxModel {
  std::array<int, 3> size{0, 0, 0};
  std::vector<std::array<uint8_t, 4>> voxels;  // x, y, z, colour index
  std::array<std::array<uint8_t, 4>, 256> palette{};
  bool has_size = false, has_voxels = false;
};

Status error(size_t offset, const std::string& what) {
  return Status::error(".vox byte " + std::to_string(offset) + ": " + what);
}

Status readChunk(Reader& r, const std::string& id, size_t content, VoxModel& model) {
  const size_t start = r.pos;
  if (id == "SIZE" && !model.has_size) {
    if (content < 12) return error(start, "SIZE chunk too short");
    for (int& s : model.size) s = int(r.u32());
    for (int s : model.size) {
      if (s < 1 || s > kMaxModelSize)
        return error(start, "model size " + std::to_string(s) + " outside 1..4096");
    }
    model.has_size = true;
  } else if (id == "XYZI" && !model.has_voxels) {
    if (!model.has_size) return error(start, "XYZI before SIZE");
    if (content < 4) return error(start, "XYZI chunk too short");
    uint32_t count = r.u32();
    if (count > (content - 4) / 4)
      return error(start, "XYZI voxel count " + std::to_string(count) + " exceeds the chunk");
    for (uint32_t i = 0; i < count; ++i) {
      std::array<uint8_t, 4> v;
      std::memcpy(v.data(), r.bytes.data() + r.pos, 4);
      r.pos += 4;
      for (int a = 0; a < 3; ++a) {
        if (v[a] >= model.size[a]) return error(r.pos - 4, "voxel outside the model size");
      }
      if (v[3] != 0) model.voxels.push_back(v);
    }
    model.has_voxels = true;
  } else if (id == "RGBA") {
    if (content < 1024) return error(start, "RGBA chunk too short");
    for (int i = 0; i < 255; ++i)
      std::memcpy(model.palette[i + 1].data(), r.bytes.data() + r.pos + 4 * i, 4);
  }
  r.pos = start + content;
  return {};
}

Expected<VoxModel> parseVox(const std::string& bytes) {
  Reader r{bytes};
  if (!r.has(8) || r.id() != "VOX ")
    return error(0, "not a MagicaVoxel file (missing 'VOX ' magic)");
  r.u32();  // version
  if (!r.has(12) || r.id() != "MAIN") return error(8, "missing MAIN chunk");
  uint32_t main_content = r.u32(), main_children = r.u32();
  if (main_content > bytes.size() - r.pos) return error(12, "MAIN content past the end");
  r.pos += main_content;
  if (main_children > bytes.size() - r.pos) return error(16, "MAIN children past the end");
  const size_t end = r.pos + main_children;
  VoxModel model;
  for (int i = 0; i < 256; ++i) model.palette[i] = {uint8_t(i), uint8_t(i), uint8_t(i), 255};
  while (r.pos < end) {
    const size_t at = r.pos;
    if (end - r.pos < 12) return error(at, "truncated chunk header");
    std::string id = r.id();
    uint32_t content = r.u32(), children = r.u32();
    if (content > end - r.pos || children > end - r.pos - content)
      return error(at, "chunk '" + id + "' past the end");
    if (Status s = readChunk(r, id, content, model); !s) return s;
    r.pos += children;
  }
  if (!model.has_size || !model.has_voxels) return error(r.pos, "no SIZE/XYZI model");
  return model;
}

Scene sceneFromModel(const VoxModel& m, const VoxImportOptions& o) {
  Scene s;
  const std::array<int, 3> dims{m.size[0], m.size[2], m.size[1]};  // ours: x, y (up), z
  for (int a = 0; a < 3; ++a) s.size[a] = (dims[a] + 15) / 16;
  std::map<uint8_t, uint8_t> palette_of;  // .vox colour index -> our palette index
  std::map<std::array<int, 3>, Block> blocks;
  for (const auto& v : m.voxels) {
    auto [it, inserted] = palette_of.emplace(v[3], uint8_t(palette_of.size() + 1));
    if (inserted) {
      const auto& c = m.palette[v[3]];
      s.palette.push_back({{c[0], c[1], c[2]}, o.roughness, o.metallic, 0});
    }
    const std::array<int, 3> p{v[0], v[2], m.size[1] - 1 - v[1]};
    Block& b = blocks[{p[0] / 16, p[1] / 16, p[2] / 16}];
    b.voxels[(p[0] % 16) + 16 * (p[1] % 16) + 256 * (p[2] % 16)] = it->second;
  }
  for (auto& [slot, block] : blocks) {
    std::string name = "vox_" + std::to_string(slot[0]) + "_" + std::to_string(slot[1]) + "_" +
                       std::to_string(slot[2]);
    s.blocks[name] = std::move(block);
    s.placements.push_back({slot, name, 0});
  }
  s.sky = Sky{{0.3, 0.5, 0.9}, {0.8, 0.85, 0.9}, {0.2, 0.18, 0.15}};
  s.sun = Sun{{0.3, 1.0, 0.2}, {3.0, 2.9, 2.7}, 0.27};
  s.ambient = {0.3, 0.32, 0.36};
  glm::dvec3 centre(s.size[0] * 0.5, s.size[1] * 0.5, s.size[2] * 0.5);
  double extent = std::max({s.size[0], s.size[1], s.size[2]});
  s.cameras = {{centre + glm::dvec3(-1.2, 0.9, -1.4) * extent, centre, 50.0}};
  return s;
}

}  // namespace

Expected<Scene> importVox(const std::string& bytes, const VoxImportOptions& options) {
  auto model = parseVox(bytes);
  if (!model) return model.status();
  if (model->voxels.empty()) return Status::error(".vox model has no voxels");
  Scene scene = sceneFromModel(*model, options);
  if (scene.palette.size() > 255) return Status::error(".vox model uses more than 255 colours");
  if (Status s = validateScene(scene); !s) return Status::error(".vox import: " + s.message());
  return scene;
}

}  // namespace rdm
