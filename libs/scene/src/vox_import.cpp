#include "rdm/scene/vox_import.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <map>
#include <set>

#include "vox_materials.h"

namespace rdm {
namespace {

// The default camera frames the model's solid voxels (block units): looking at the centre
// of their box from above and to the side, far enough that the box's bounding sphere fits
// the vertical field of view (the horizontal one is wider at every usual aspect).
Camera frameVoxels(glm::dvec3 lo, glm::dvec3 hi, const std::array<int, 3>& size) {
  if (lo.x > hi.x) lo = glm::dvec3(0.0), hi = glm::dvec3(size[0], size[1], size[2]);
  constexpr double kFovDeg = 50.0;
  const glm::dvec3 centre = (lo + hi) * 0.5;
  const double radius = std::max(0.5 * glm::length(hi - lo), 0.25);
  const double distance = 1.1 * radius / std::sin(glm::radians(kFovDeg) * 0.5);
  const glm::dvec3 from = glm::normalize(glm::dvec3(-1.2, 0.9, -1.4));
  return {centre + from * distance, centre, kFovDeg};
}

using vox::Dict;

constexpr int kMaxModelSize = 256 * 16;  // the grid's limit in voxels
constexpr int kMaxGraphDepth = 256;
constexpr long long kMaxTranslation = 100000;  // per node; depth 256 stays far from int limits
// Shared subgraphs multiply: bound the walk and the voxels it places.
constexpr int kMaxGraphVisits = 1 << 20;
constexpr uint64_t kMaxPlacedVoxels = uint64_t(1) << 26;

Status error(size_t offset, const std::string& what) {
  return Status::error(".vox byte " + std::to_string(offset) + ": " + what);
}

// Bounds-checked little-endian reads inside [pos, end).
struct Reader {
  const std::string& bytes;
  size_t pos = 0, end = 0;
  std::string chunk;  // named in errors
  Status fail(const std::string& what) const { return error(pos, chunk + ": " + what); }
  bool has(size_t n) const { return n <= end - pos; }
  Status i32(int32_t& v) {
    if (!has(4)) return fail("truncated");
    std::memcpy(&v, bytes.data() + pos, 4);  // .vox is little-endian, as is every target here
    pos += 4;
    return {};
  }
  Status str(std::string& s) {
    int32_t n = 0;
    if (Status st = i32(n); !st) return st;
    if (n < 0 || !has(size_t(n)))
      return fail("string length " + std::to_string(n) + " past the chunk");
    s = bytes.substr(pos, size_t(n));
    pos += size_t(n);
    return {};
  }
  Status dict(Dict& d) {
    int32_t n = 0;
    if (Status st = i32(n); !st) return st;
    if (n < 0 || size_t(n) > (end - pos) / 8) return fail("dictionary size past the chunk");
    for (int32_t i = 0; i < n; ++i) {
      std::string k, v;
      if (Status st = str(k); !st) return st;
      if (Status st = str(v); !st) return st;
      d[k] = v;
    }
    return {};
  }
};

struct Model {
  std::array<int, 3> size{0, 0, 0};
  std::vector<std::array<uint8_t, 4>> voxels;  // x, y, z, colour index
  bool has_voxels = false;
};

struct Node {
  char kind = 0;  // 'T', 'G', 'S'
  Dict attributes, frame;
  int layer = -1;
  int frames = 1;
  std::vector<int> children;  // T: one child; G: children; S: model ids
};

struct VoxFile {
  std::vector<Model> models;
  std::array<std::array<uint8_t, 4>, 256> palette = voxDefaultPalette();
  bool has_rgba = false;
  std::map<int, Dict> materials;
  std::map<int, Node> nodes;
  std::set<int> hidden_layers;
};

bool isHidden(const Dict& d) {
  auto it = d.find("_hidden");
  return it != d.end() && it->second == "1";
}

Status readModelChunk(Reader& r, const std::string& id, VoxFile& f) {
  if (id == "SIZE") {
    Model m;
    for (int& s : m.size) {
      int32_t v = 0;
      if (Status st = r.i32(v); !st) return st;
      if (v < 1 || v > kMaxModelSize)
        return r.fail("model size " + std::to_string(v) + " outside 1..4096");
      s = v;
    }
    f.models.push_back(std::move(m));
    return {};
  }
  // XYZI
  if (f.models.empty() || f.models.back().has_voxels) return r.fail("XYZI without its SIZE");
  Model& m = f.models.back();
  int32_t count = 0;
  if (Status st = r.i32(count); !st) return st;
  if (count < 0 || size_t(count) > (r.end - r.pos) / 4)
    return r.fail("voxel count " + std::to_string(count) + " exceeds the chunk");
  for (int32_t i = 0; i < count; ++i) {
    std::array<uint8_t, 4> v;
    std::memcpy(v.data(), r.bytes.data() + r.pos, 4);
    for (int a = 0; a < 3; ++a) {
      if (v[size_t(a)] >= m.size[size_t(a)]) return r.fail("voxel outside the model size");
    }
    r.pos += 4;
    if (v[3] != 0) m.voxels.push_back(v);
  }
  m.has_voxels = true;
  return {};
}

Status readNodeChunk(Reader& r, const std::string& id, VoxFile& f) {
  int32_t node_id = 0;
  Node node;
  node.kind = id[1] == 'T' ? 'T' : id[1] == 'G' ? 'G' : 'S';
  if (Status s = r.i32(node_id); !s) return s;
  if (Status s = r.dict(node.attributes); !s) return s;
  int32_t n = 0;
  if (node.kind == 'T') {
    int32_t child = 0, reserved = 0, layer = 0;
    for (int32_t* v : {&child, &reserved, &layer, &n}) {
      if (Status s = r.i32(*v); !s) return s;
    }
    node.children = {child};
    node.layer = layer;
    node.frames = n;
    if (n >= 1) {
      if (Status s = r.dict(node.frame); !s) return s;
    }
  } else {
    if (Status s = r.i32(n); !s) return s;
    if (n < 0 || size_t(n) > (r.end - r.pos) / 4) return r.fail("child count past the chunk");
    for (int32_t i = 0; i < n; ++i) {
      int32_t child = 0;
      if (Status s = r.i32(child); !s) return s;
      if (node.kind == 'S') {
        Dict model_attributes;
        if (Status s = r.dict(model_attributes); !s) return s;
      }
      node.children.push_back(child);
    }
  }
  if (!f.nodes.emplace(node_id, std::move(node)).second)
    return r.fail("node id " + std::to_string(node_id) + " used twice");
  return {};
}

Status readChunk(Reader& r, const std::string& id, VoxFile& f) {
  if (id == "SIZE" || id == "XYZI") return readModelChunk(r, id, f);
  if (id == "nTRN" || id == "nGRP" || id == "nSHP") return readNodeChunk(r, id, f);
  if (id == "RGBA") {
    if (!r.has(1024)) return r.fail("RGBA chunk too short");
    for (size_t i = 0; i < 255; ++i)
      std::memcpy(f.palette[i + 1].data(), r.bytes.data() + r.pos + 4 * i, 4);
    f.has_rgba = true;
  } else if (id == "MATL") {
    int32_t material = 0;
    if (Status s = r.i32(material); !s) return s;
    Dict d;
    if (Status s = r.dict(d); !s) return s;
    if (material >= 0 && material < 256) f.materials[material] = std::move(d);
  } else if (id == "LAYR") {
    int32_t layer = 0;
    if (Status s = r.i32(layer); !s) return s;
    Dict d;
    if (Status s = r.dict(d); !s) return s;
    if (isHidden(d)) f.hidden_layers.insert(layer);
  }
  return {};
}

Expected<VoxFile> parseVox(const std::string& bytes) {
  Reader r{bytes, 0, bytes.size(), "header"};
  if (bytes.size() < 8 || bytes.compare(0, 4, "VOX ") != 0)
    return error(0, "not a MagicaVoxel file (missing 'VOX ' magic)");
  r.pos = 8;
  if (bytes.size() < 20 || bytes.compare(8, 4, "MAIN") != 0) return error(8, "missing MAIN chunk");
  r.pos = 12;
  int32_t main_content = 0, main_children = 0;
  (void)r.i32(main_content), (void)r.i32(main_children);
  if (main_content < 0 || size_t(main_content) > bytes.size() - r.pos)
    return error(12, "MAIN content past the end");
  r.pos += size_t(main_content);
  if (main_children < 0 || size_t(main_children) > bytes.size() - r.pos)
    return error(16, "MAIN children past the end");
  const size_t end = r.pos + size_t(main_children);
  VoxFile f;
  while (r.pos < end) {
    const size_t at = r.pos;
    if (end - r.pos < 12) return error(at, "truncated chunk header");
    const std::string id = bytes.substr(r.pos, 4);
    uint32_t content = 0, children = 0;
    std::memcpy(&content, bytes.data() + r.pos + 4, 4);
    std::memcpy(&children, bytes.data() + r.pos + 8, 4);
    r.pos += 12;
    if (content > end - r.pos || children > end - r.pos - content)
      return error(at, "chunk '" + id + "' past the end");
    Reader chunk{bytes, r.pos, r.pos + content, "chunk '" + id + "'"};
    if (Status s = readChunk(chunk, id, f); !s) return s;
    r.pos += content + children;
  }
  if (f.models.empty() || !f.models.back().has_voxels) return error(r.pos, "no SIZE/XYZI model");
  return f;
}

// A rotation (integer matrix, rows) and translation, applied as R p + t.
struct Transform {
  std::array<std::array<int, 3>, 3> r{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  std::array<int, 3> t{0, 0, 0};
  std::array<int, 3> apply(const std::array<int, 3>& p) const {
    std::array<int, 3> out{};
    for (size_t i = 0; i < 3; ++i) out[i] = r[i][0] * p[0] + r[i][1] * p[1] + r[i][2] * p[2];
    return out;
  }
  Transform then(const Transform& child) const {  // this * child
    Transform out;
    for (size_t i = 0; i < 3; ++i)
      for (size_t j = 0; j < 3; ++j)
        out.r[i][j] = r[i][0] * child.r[0][j] + r[i][1] * child.r[1][j] + r[i][2] * child.r[2][j];
    std::array<int, 3> moved = apply(child.t);
    for (size_t i = 0; i < 3; ++i) out.t[i] = moved[i] + t[i];
    return out;
  }
};

Expected<Transform> frameTransform(const Dict& frame, int node_id) {
  Transform x;
  const std::string where = "nTRN " + std::to_string(node_id);
  if (auto it = frame.find("_r"); it != frame.end()) {
    const long parsed = std::strtol(it->second.c_str(), nullptr, 10);
    const int bits = parsed < 0 || parsed > 127 ? -1 : int(parsed);
    const int i0 = bits & 3, i1 = (bits >> 2) & 3, i2 = 3 - i0 - i1;
    if (bits < 0 || bits > 127 || i0 > 2 || i1 > 2 || i0 == i1)
      return Status::error(".vox " + where + ": rotation _r " + it->second + " is not a rotation");
    x.r = {};
    const int index[3] = {i0, i1, i2};
    for (size_t row = 0; row < 3; ++row)
      x.r[row][size_t(index[row])] = (bits >> (4 + row)) & 1 ? -1 : 1;
  }
  if (auto it = frame.find("_t"); it != frame.end()) {
    const char* text = it->second.c_str();
    for (int& v : x.t) {
      char* end = nullptr;
      const long long parsed = std::strtoll(text, &end, 10);
      if (end == text)
        return Status::error(".vox " + where + ": translation _t '" + it->second + "' malformed");
      if (parsed < -kMaxTranslation || parsed > kMaxTranslation)
        return Status::error(".vox " + where + ": translation outside +-100000");
      v = int(parsed);
      text = end;
    }
  }
  return x;
}

struct Instance {
  int model = 0;
  Transform transform;
};

struct GraphWalk {
  const VoxFile& file;
  VoxImportReport& report;
  std::vector<Instance> instances;
  bool frames_dropped = false;

  int visits = 0;
  uint64_t placed = 0;
  std::set<int> on_path;

  Status enter(int id, int depth) {
    if (depth > kMaxGraphDepth) return Status::error(".vox scene graph deeper than 256");
    if (++visits > kMaxGraphVisits)
      return Status::error(".vox scene graph too large: more than 2^20 node visits");
    if (on_path.count(id))
      return Status::error(".vox scene graph: node " + std::to_string(id) + " is its own ancestor");
    return {};
  }

  Status visit(int id, const Transform& parent, int depth) {
    if (Status s = enter(id, depth); !s) return s;
    on_path.insert(id);
    Status s = visitNode(id, parent, depth);
    on_path.erase(id);
    return s;
  }

  Status visitNode(int id, const Transform& parent, int depth) {
    auto it = file.nodes.find(id);
    if (it == file.nodes.end())
      return Status::error(".vox scene graph: node " + std::to_string(id) + " is missing");
    const Node& n = it->second;
    if (n.kind == 'T') {
      auto local = frameTransform(n.frame, id);
      if (!local) return local.status();
      frames_dropped |= n.frames > 1;
      if (isHidden(n.attributes) || file.hidden_layers.count(n.layer))
        return countHidden(n.children[0], depth + 1);
      return visit(n.children[0], parent.then(*local), depth + 1);
    }
    if (n.kind == 'G') {
      for (int child : n.children) {
        if (Status s = visit(child, parent, depth + 1); !s) return s;
      }
      return {};
    }
    frames_dropped |= n.children.size() > 1;
    if (n.children.empty()) return {};
    const int model = n.children[0];
    if (model < 0 || size_t(model) >= file.models.size())
      return Status::error(".vox nSHP " + std::to_string(id) + ": model " + std::to_string(model) +
                           " does not exist");
    placed += file.models[size_t(model)].voxels.size();
    if (placed > kMaxPlacedVoxels)
      return Status::error(".vox scene graph places more than 2^26 voxels");
    instances.push_back({model, parent});
    return {};
  }
  Status countHidden(int id, int depth) {
    if (Status s = enter(id, depth); !s) return s;
    auto it = file.nodes.find(id);
    if (it == file.nodes.end()) return {};
    if (it->second.kind == 'S') {
      ++report.hidden;
      return {};
    }
    on_path.insert(id);
    for (int child : it->second.children) {
      if (Status s = countHidden(child, depth + 1); !s) return on_path.erase(id), s;
    }
    on_path.erase(id);
    return {};
  }
};

// The voxel (x, y, z) of a model of `size` whose centre sits at the transform's origin:
// floor(R (v + 1/2 - size/2) + t), in doubled integer coordinates.
std::array<int, 3> place(const std::array<uint8_t, 4>& v, const std::array<int, 3>& size,
                         const Transform& x) {
  std::array<int, 3> d{};
  for (size_t a = 0; a < 3; ++a) d[a] = 2 * int(v[a]) + 1 - size[a];
  std::array<int, 3> w = x.apply(d);
  for (size_t a = 0; a < 3; ++a) {
    const int doubled = w[a] + 2 * x.t[a];
    w[a] = doubled >= 0 ? doubled / 2 : -((-doubled + 1) / 2);
  }
  return w;
}

Expected<Scene> buildScene(const VoxFile& f, const std::vector<Instance>& instances,
                           const VoxImportOptions& o, VoxImportReport& report) {
  // Two passes over the placed voxels (MagicaVoxel world coordinates, z up): their box, then
  // the blocks; nothing is stored in between.
  auto forEachVoxel = [&](const auto& fn) {
    for (const Instance& inst : instances) {
      const Model& m = f.models[size_t(inst.model)];
      for (const auto& v : m.voxels) {
        fn(report.scene_graph ? place(v, m.size, inst.transform)
                              : std::array<int, 3>{int(v[0]), int(v[1]), int(v[2])},
           v[3]);
      }
    }
  };
  std::array<int, 3> lo{INT_MAX, INT_MAX, INT_MAX}, hi{INT_MIN, INT_MIN, INT_MIN};
  bool any = false;
  forEachVoxel([&](const std::array<int, 3>& p, uint8_t) {
    any = true;
    for (size_t a = 0; a < 3; ++a) lo[a] = std::min(lo[a], p[a]), hi[a] = std::max(hi[a], p[a]);
  });
  if (!any) return Status::error(".vox file places no voxels");
  for (size_t a = 0; a < 3; ++a) {
    if (hi[a] - lo[a] + 1 > kMaxModelSize)
      return Status::error(".vox models span " + std::to_string(hi[a] - lo[a] + 1) +
                           " voxels along " + "xyz"[a] + ", more than 4096");
  }
  Scene s;
  const std::array<int, 3> dims{hi[0] - lo[0] + 1, hi[2] - lo[2] + 1, hi[1] - lo[1] + 1};
  for (size_t a = 0; a < 3; ++a) s.size[a] = (dims[a] + 15) / 16;
  vox::MaterialNotes notes;
  std::map<uint8_t, uint8_t> palette_of;  // .vox colour index -> our palette index
  std::map<std::array<int, 3>, Block> blocks;
  glm::dvec3 box_lo(1e30), box_hi(-1e30);  // solid voxels, in voxel units
  forEachVoxel([&](const std::array<int, 3>& at, uint8_t colour) {
    auto [it, inserted] = palette_of.emplace(colour, uint8_t(palette_of.size() + 1));
    if (inserted) {
      auto m = f.materials.find(colour);
      s.palette.push_back(vox::mapMaterial(
          colour, f.palette[colour], m == f.materials.end() ? nullptr : &m->second, o, notes));
    }
    const int x = at[0] - lo[0], y = at[1] - lo[1], z = at[2] - lo[2];
    const std::array<int, 3> p{x, z, dims[2] - 1 - y};
    for (int i = 0; i < 3; ++i)
      box_lo[i] = std::min(box_lo[i], double(p[i])), box_hi[i] = std::max(box_hi[i], p[i] + 1.0);
    Block& b = blocks[{p[0] / 16, p[1] / 16, p[2] / 16}];
    uint8_t& cell = b.voxels[size_t((p[0] % 16) + 16 * (p[1] % 16) + 256 * (p[2] % 16))];
    report.voxels += cell == 0 ? 1 : 0;
    cell = it->second;
  });
  if (s.palette.size() > 255) return Status::error(".vox model uses more than 255 colours");
  notes.finish(report);
  s.emission_scale = notes.emissionScale();
  for (auto& [slot, block] : blocks) {
    std::string name = "vox_" + std::to_string(slot[0]) + "_" + std::to_string(slot[1]) + "_" +
                       std::to_string(slot[2]);
    s.blocks[name] = std::move(block);
    s.placements.push_back({slot, name, 0});
  }
  s.sky = Sky{{0.3, 0.5, 0.9}, {0.8, 0.85, 0.9}, {0.2, 0.18, 0.15}};
  s.sun = Sun{{0.3, 1.0, 0.2}, {3.0, 2.9, 2.7}, 0.27};
  s.ambient = {0.3, 0.32, 0.36};
  s.cameras = {frameVoxels(box_lo / 16.0, box_hi / 16.0, s.size)};
  return s;
}

}  // namespace

Expected<Scene> importVox(const std::string& bytes, const VoxImportOptions& options,
                          VoxImportReport* report_out) {
  auto file = parseVox(bytes);
  if (!file) return file.status();
  VoxImportReport report;
  report.models = int(file->models.size());
  report.default_palette = !file->has_rgba;
  GraphWalk walk{*file, report, {}, false};
  if (file->nodes.count(0)) {
    report.scene_graph = true;
    if (Status s = walk.visit(0, Transform{}, 0); !s) return s;
  } else {
    for (int m = 0; m < report.models; ++m) walk.instances.push_back({m, Transform{}});
  }
  report.instances = int(walk.instances.size());
  if (walk.frames_dropped) report.dropped.push_back("animation frames after the first");
  if (report.hidden > 0)
    report.dropped.push_back(std::to_string(report.hidden) +
                             " hidden shape(s) (hidden node or layer)");
  auto scene = buildScene(*file, walk.instances, options, report);
  if (!scene) return scene;
  vox::chooseBakeDefaults(*scene, report.chosen);
  if (Status s = validateScene(*scene); !s) return Status::error(".vox import: " + s.message());
  if (report_out) *report_out = std::move(report);
  return scene;
}

}  // namespace rdm
