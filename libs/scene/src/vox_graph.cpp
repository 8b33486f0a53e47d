#include "vox_graph.h"

#include <algorithm>
#include <cstdlib>

namespace rdm::vox {

std::array<int, 3> Transform::apply(const std::array<int, 3>& p) const {
  std::array<int, 3> out{};
  for (size_t i = 0; i < 3; ++i) out[i] = r[i][0] * p[0] + r[i][1] * p[1] + r[i][2] * p[2];
  return out;
}

Transform Transform::then(const Transform& child) const {
  Transform out;
  for (size_t i = 0; i < 3; ++i)
    for (size_t j = 0; j < 3; ++j)
      out.r[i][j] = r[i][0] * child.r[0][j] + r[i][1] * child.r[1][j] + r[i][2] * child.r[2][j];
  std::array<int, 3> moved = apply(child.t);
  for (size_t i = 0; i < 3; ++i) out.t[i] = moved[i] + t[i];
  return out;
}

namespace {

// Shared subgraphs multiply: bound the walk and the voxels it places.
constexpr int kMaxGraphVisits = 1 << 20;
constexpr uint64_t kMaxPlacedVoxels = uint64_t(1) << 26;

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

struct GraphWalk {
  const VoxFile& file;
  int frame = 0;
  const std::set<int>& shown;
  VoxImportReport& report;
  std::vector<Instance> instances;
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

  bool hidden(const Node& n) const {
    if (isHidden(n.attributes)) return true;
    auto layer = file.layers.find(n.layer);
    return layer != file.layers.end() && layer->second.hidden && !shown.count(n.layer);
  }

  Status visitNode(int id, const Transform& parent, int depth) {
    auto it = file.nodes.find(id);
    if (it == file.nodes.end())
      return Status::error(".vox scene graph: node " + std::to_string(id) + " is missing");
    const Node& n = it->second;
    if (n.kind == 'T') {
      const Keyframe* key = keyframeAt(n.keyframes, frame);
      auto local = frameTransform(key ? key->values : Dict{}, id);
      if (!local) return local.status();
      if (hidden(n)) return countHidden(n.children[0], depth + 1);
      return visit(n.children[0], parent.then(*local), depth + 1);
    }
    if (n.kind == 'G') {
      for (int child : n.children) {
        if (Status s = visit(child, parent, depth + 1); !s) return s;
      }
      return {};
    }
    const Keyframe* key = keyframeAt(n.keyframes, frame);
    if (!key) return {};
    return placeModel(id, key->model, parent);
  }

  Status placeModel(int node_id, int model, const Transform& x) {
    if (model < 0 || size_t(model) >= file.models.size())
      return Status::error(".vox nSHP " + std::to_string(node_id) + ": model " +
                           std::to_string(model) + " does not exist");
    placed += file.models[size_t(model)].voxels.size();
    if (placed > kMaxPlacedVoxels)
      return Status::error(".vox scene graph places more than 2^26 voxels");
    instances.push_back({model, x});
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

std::string layerList(const VoxFile& f) {
  std::string out;
  for (const auto& [id, layer] : f.layers) {
    out += (out.empty() ? "" : ", ") + std::to_string(id);
    if (!layer.name.empty() && layer.name != std::to_string(id)) out += " '" + layer.name + "'";
    if (layer.hidden) out += " (hidden)";
  }
  return out.empty() ? "none" : out;
}

}  // namespace

int frameCount(const VoxFile& f, bool scene_graph) {
  if (!scene_graph) return int(f.models.size());
  int last = 0;
  for (const auto& [id, node] : f.nodes) {
    for (const Keyframe& k : node.keyframes) last = std::max(last, k.frame);
  }
  return last + 1;
}

Expected<std::set<int>> chooseLayers(const VoxFile& f, const std::vector<std::string>& names) {
  std::set<int> ids;
  for (const std::string& name : names) {
    auto it = std::find_if(f.layers.begin(), f.layers.end(), [&](const auto& l) {
      return l.second.name == name || std::to_string(l.first) == name;
    });
    if (it == f.layers.end())
      return Status::error(".vox has no layer '" + name + "'; its layers: " + layerList(f));
    ids.insert(it->first);
  }
  return ids;
}

Expected<std::vector<Instance>> walkGraph(const VoxFile& f, int frame, const std::set<int>& shown,
                                          VoxImportReport& report) {
  GraphWalk walk{f, frame, shown, report, {}};
  if (Status s = walk.visit(0, Transform{}, 0); !s) return s;
  return std::move(walk.instances);
}

}  // namespace rdm::vox
