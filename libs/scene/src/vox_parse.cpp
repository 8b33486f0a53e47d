#include "vox_parse.h"

#include <cstdlib>
#include <cstring>

namespace rdm::vox {

Status error(size_t offset, const std::string& what) {
  return Status::error(".vox byte " + std::to_string(offset) + ": " + what);
}

Status Reader::fail(const std::string& what) const {
  return error(pos, chunk + ": " + what);
}

Status Reader::i32(int32_t& v) {
  if (!has(4)) return fail("truncated");
  std::memcpy(&v, bytes.data() + pos, 4);  // .vox is little-endian, as is every target here
  pos += 4;
  return {};
}

Status Reader::str(std::string& s) {
  int32_t n = 0;
  if (Status st = i32(n); !st) return st;
  if (n < 0 || !has(size_t(n)))
    return fail("string length " + std::to_string(n) + " past the chunk");
  s = bytes.substr(pos, size_t(n));
  pos += size_t(n);
  return {};
}

Status Reader::dict(Dict& d) {
  int32_t n = 0;
  if (Status st = i32(n); !st) return st;
  if (n < 0 || size_t(n) > (end - pos) / 8)
    return fail("dictionary size " + std::to_string(n) + " past the chunk");
  for (int32_t i = 0; i < n; ++i) {
    std::string k, v;
    if (Status st = str(k); !st) return st;
    if (Status st = str(v); !st) return st;
    d[k] = v;
  }
  return {};
}

bool isHidden(const Dict& d) {
  auto it = d.find("_hidden");
  return it != d.end() && it->second == "1";
}

const Keyframe* keyframeAt(const std::vector<Keyframe>& keys, int frame) {
  const Keyframe* best = nullptr;
  for (const Keyframe& k : keys) {
    if (k.frame <= frame && (!best || k.frame >= best->frame)) best = &k;
  }
  return best || keys.empty() ? best : &keys.front();
}

namespace {

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
  if (f.models.empty() || f.models.back().has_voxels) return r.fail("XYZI without its SIZE");
  Model& m = f.models.back();
  int32_t count = 0;
  if (Status st = r.i32(count); !st) return st;
  if (count < 0 || size_t(count) > (r.end - r.pos) / 4)
    return r.fail("voxel count " + std::to_string(count) + " exceeds the chunk");
  for (int32_t i = 0; i < count; ++i) {
    std::array<uint8_t, 4> v;
    std::memcpy(v.data(), r.bytes.data() + r.pos, 4);
    for (size_t a = 0; a < 3; ++a) {
      if (v[a] >= m.size[a]) return r.fail("voxel outside the model size");
    }
    r.pos += 4;
    if (v[3] != 0) m.voxels.push_back(v);
  }
  m.has_voxels = true;
  return {};
}

// `_f` of a keyframe dictionary: a frame index in 0..kMaxFrames-1, else `fallback`.
Status frameIndex(const Reader& r, const Dict& d, int fallback, int& frame) {
  frame = fallback;
  auto it = d.find("_f");
  if (it == d.end()) return {};
  char* end = nullptr;
  const long v = std::strtol(it->second.c_str(), &end, 10);
  if (end == it->second.c_str() || v < 0 || v >= kMaxFrames)
    return r.fail("frame index _f '" + it->second + "' outside 0.." +
                  std::to_string(kMaxFrames - 1));
  frame = int(v);
  return {};
}

Status readKeyframes(Reader& r, Node& node, int32_t n) {
  const size_t least = node.kind == 'T' ? 4 : 8;  // an empty dictionary (and a model id)
  if (n < 0 || size_t(n) > (r.end - r.pos) / least)
    return r.fail((node.kind == 'T' ? "frame count " : "model count ") + std::to_string(n) +
                  " past the chunk");
  for (int32_t i = 0; i < n; ++i) {
    Keyframe k;
    if (node.kind == 'S') {
      int32_t model = 0;
      if (Status s = r.i32(model); !s) return s;
      k.model = model;
    }
    if (Status s = r.dict(k.values); !s) return s;
    if (Status s = frameIndex(r, k.values, int(i), k.frame); !s) return s;
    node.keyframes.push_back(std::move(k));
  }
  return {};
}

Status readNodeChunk(Reader& r, const std::string& id, VoxFile& f) {
  int32_t node_id = 0, n = 0;
  Node node;
  node.kind = id[1];
  if (Status s = r.i32(node_id); !s) return s;
  if (Status s = r.dict(node.attributes); !s) return s;
  if (node.kind == 'T') {
    int32_t child = 0, reserved = 0, layer = 0;
    for (int32_t* v : {&child, &reserved, &layer, &n}) {
      if (Status s = r.i32(*v); !s) return s;
    }
    node.children = {child};
    node.layer = layer;
    if (Status s = readKeyframes(r, node, n); !s) return s;
  } else if (node.kind == 'G') {
    if (Status s = r.i32(n); !s) return s;
    if (n < 0 || size_t(n) > (r.end - r.pos) / 4)
      return r.fail("child count " + std::to_string(n) + " past the chunk");
    for (int32_t i = 0; i < n; ++i) {
      int32_t child = 0;
      if (Status s = r.i32(child); !s) return s;
      node.children.push_back(child);
    }
  } else {
    if (Status s = r.i32(n); !s) return s;
    if (Status s = readKeyframes(r, node, n); !s) return s;
  }
  if (!f.nodes.emplace(node_id, std::move(node)).second)
    return r.fail("node id " + std::to_string(node_id) + " used twice");
  return {};
}

// An id followed by a dictionary: MATL, LAYR, rCAM.
Status readIdDict(Reader& r, int32_t& id, Dict& d) {
  if (Status s = r.i32(id); !s) return s;
  return r.dict(d);
}

Status readChunk(Reader& r, const std::string& id, VoxFile& f) {
  if (id == "SIZE" || id == "XYZI") return readModelChunk(r, id, f);
  if (id == "nTRN" || id == "nGRP" || id == "nSHP") return readNodeChunk(r, id, f);
  int32_t n = 0;
  Dict d;
  if (id == "RGBA") {
    if (!r.has(1024)) return r.fail("RGBA chunk too short");
    for (size_t i = 0; i < 255; ++i)
      std::memcpy(f.palette[i + 1].data(), r.bytes.data() + r.pos + 4 * i, 4);
    f.has_rgba = true;
  } else if (id == "PACK") {
    if (Status s = r.i32(n); !s) return s;
    if (n < 1 || n > kMaxFrames)
      return r.fail("model count " + std::to_string(n) + " outside 1..65536");
    f.pack_models = n;
  } else if (id == "MATL" || id == "LAYR" || id == "rCAM") {
    if (Status s = readIdDict(r, n, d); !s) return s;
    if (id == "MATL" && n >= 0 && n < 256) f.materials[n] = std::move(d);
    if (id == "LAYR") f.layers[n] = {d.count("_name") ? d["_name"] : "", isHidden(d)};
    if (id == "rCAM") f.cameras[n] = std::move(d);
  } else if (id == "rOBJ" || id == "rLIT" || id == "rAIR") {
    if (Status s = r.dict(d); !s) return s;
    d["_chunk"] = id;
    f.render_objects.push_back(std::move(d));
  }
  return {};
}

}  // namespace

Expected<VoxFile> parseVox(const std::string& bytes) {
  Reader r{bytes, 0, bytes.size(), "header"};
  if (bytes.size() < 8 || bytes.compare(0, 4, "VOX ") != 0)
    return error(0, "not a MagicaVoxel file (missing 'VOX ' magic)");
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
  f.palette = voxDefaultPalette();
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

}  // namespace rdm::vox
