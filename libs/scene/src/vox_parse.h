// The chunks of a MagicaVoxel .vox file read into a VoxFile (vox_parse.cpp): models, palette,
// materials, scene graph, layers, the PACK model count, render objects (rOBJ, rLIT, rAIR) and
// cameras (rCAM). Every read is bounds-checked; errors name the chunk and byte offset.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "rdm/base/status.h"
#include "vox_materials.h"

namespace rdm::vox {

// Limits on what a file may ask for: the grid's extent, scene-graph depth, translations per
// node (depth 256 stays far from int limits) and animation frames.
constexpr int kMaxModelSize = 256 * 16;
constexpr int kMaxGraphDepth = 256;
constexpr long long kMaxTranslation = 100000;
constexpr int kMaxFrames = 1 << 16;

Status error(size_t offset, const std::string& what);

// Bounds-checked little-endian reads inside [pos, end) of one chunk.
struct Reader {
  const std::string& bytes;
  size_t pos = 0, end = 0;
  std::string chunk;  // named in errors
  Status fail(const std::string& what) const;
  bool has(size_t n) const { return n <= end - pos; }
  Status i32(int32_t& v);
  Status str(std::string& s);
  Status dict(Dict& d);
};

struct Model {
  std::array<int, 3> size{0, 0, 0};
  std::vector<std::array<uint8_t, 4>> voxels;  // x, y, z, colour index
  bool has_voxels = false;
};

// A keyframe of an nTRN (its frame dictionary) or an nSHP (model id and its attributes).
struct Keyframe {
  int frame = 0;  // `_f`, else the position in the chunk
  Dict values;
  int model = -1;  // nSHP only
};

struct Node {
  char kind = 0;  // 'T', 'G', 'S'
  Dict attributes;
  int layer = -1;
  std::vector<int> children;        // T: one child; G: children
  std::vector<Keyframe> keyframes;  // T: frame dictionaries; S: models
};

struct Layer {
  std::string name;
  bool hidden = false;
};

struct VoxFile {
  std::vector<Model> models;
  std::array<std::array<uint8_t, 4>, 256> palette{};
  bool has_rgba = false;
  int pack_models = -1;  // PACK's count; -1: no PACK chunk
  std::map<int, Dict> materials;
  std::map<int, Node> nodes;
  std::map<int, Layer> layers;
  std::vector<Dict> render_objects;  // rOBJ, and rLIT/rAIR with their chunk id as `_chunk`
  std::map<int, Dict> cameras;       // rCAM by camera id
};

Expected<VoxFile> parseVox(const std::string& bytes);

// The keyframe in effect at `frame`: the last one whose frame is <= `frame`, else the first.
const Keyframe* keyframeAt(const std::vector<Keyframe>& keys, int frame);

bool isHidden(const Dict& d);

}  // namespace rdm::vox
