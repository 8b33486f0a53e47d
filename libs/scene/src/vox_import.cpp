#include "rdm/scene/vox_import.h"

#include <algorithm>
#include <climits>
#include <cstdint>
#include <map>

#include "vox_cameras.h"
#include "vox_graph.h"
#include "vox_lights.h"
#include "vox_materials.h"
#include "vox_parse.h"

namespace rdm {
namespace {

using vox::Instance;
using vox::VoxFile;

// The ground's palette entry: light grey, diffuse. Colour index 0 (empty in .vox) stands for it.
constexpr uint8_t kGroundColour = 0;
const PaletteEntry kGroundEntry{{200, 200, 200}, 7, 0, 0};
// Bounds the floor's blocks (and memory) for a sparse model with a huge footprint.
constexpr int64_t kMaxGroundVoxels = int64_t(2048) * 2048;

// The voxel (x, y, z) of a model of `size` whose centre sits at the transform's origin:
// floor(R (v + 1/2 - size/2) + t), in doubled integer coordinates.
std::array<int, 3> place(const std::array<uint8_t, 4>& v, const std::array<int, 3>& size,
                         const vox::Transform& x) {
  std::array<int, 3> d{};
  for (size_t a = 0; a < 3; ++a) d[a] = 2 * int(v[a]) + 1 - size[a];
  std::array<int, 3> w = x.apply(d);
  for (size_t a = 0; a < 3; ++a) {
    const int doubled = w[a] + 2 * x.t[a];
    w[a] = doubled >= 0 ? doubled / 2 : -((-doubled + 1) / 2);
  }
  return w;
}

using Box = std::array<std::array<int, 3>, 2>;  // lo, hi: inclusive voxel indices

// The placed voxels in MagicaVoxel world coordinates (z up): the models' voxels, then the
// ground (a floor under the box `ground` when its lo[0] <= hi[0]).
struct PlacedVoxels {
  const VoxFile& f;
  const std::vector<Instance>& instances;
  bool scene_graph = false;
  Box ground{{{0, 0, 0}, {-1, -1, -1}}};

  template <typename Fn>
  void forEach(const Fn& fn) const {
    for (const Instance& inst : instances) {
      const vox::Model& m = f.models[size_t(inst.model)];
      for (const auto& v : m.voxels) {
        fn(scene_graph ? place(v, m.size, inst.transform)
                       : std::array<int, 3>{int(v[0]), int(v[1]), int(v[2])},
           v[3]);
      }
    }
    for (int x = ground[0][0]; x <= ground[1][0]; ++x)
      for (int y = ground[0][1]; y <= ground[1][1]; ++y) fn({x, y, ground[0][2]}, kGroundColour);
  }

  Expected<Box> box() const {
    Box b{{{INT_MAX, INT_MAX, INT_MAX}, {INT_MIN, INT_MIN, INT_MIN}}};
    forEach([&](const std::array<int, 3>& p, uint8_t) {
      for (size_t a = 0; a < 3; ++a)
        b[0][a] = std::min(b[0][a], p[a]), b[1][a] = std::max(b[1][a], p[a]);
    });
    if (b[0][0] > b[1][0]) return Status::error(".vox file places no voxels");
    for (size_t a = 0; a < 3; ++a) {
      if (b[1][a] - b[0][a] + 1 > vox::kMaxModelSize)
        return Status::error(".vox models span " + std::to_string(b[1][a] - b[0][a] + 1) +
                             " voxels along " + "xyz"[a] + ", more than 4096");
    }
    return b;
  }
};

// The ground under `model` (the models' box): kGroundMargin wider each side, one voxel below.
Box groundUnder(const Box& model) {
  Box g = model;
  for (size_t a = 0; a < 2; ++a) g[0][a] -= kGroundMargin, g[1][a] += kGroundMargin;
  g[0][2] = g[1][2] = model[0][2] - 1;
  return g;
}

Status addGround(const Box& model, PlacedVoxels& placed) {
  placed.ground = groundUnder(model);
  const int64_t w = placed.ground[1][0] - placed.ground[0][0] + 1,
                d = placed.ground[1][1] - placed.ground[0][1] + 1;
  if (w * d > kMaxGroundVoxels)
    return Status::error(".vox --ground: a " + std::to_string(w) + " x " + std::to_string(d) +
                         " voxel floor is more than 2048 x 2048");
  return {};
}

// Names each block by its slot ("vox_X_Y_Z") and places it unrotated.
void addBlocks(std::map<std::array<int, 3>, Block>& blocks, Scene& s) {
  for (auto& [slot, block] : blocks) {
    std::string name = "vox_" + std::to_string(slot[0]) + "_" + std::to_string(slot[1]) + "_" +
                       std::to_string(slot[2]);
    s.blocks[name] = std::move(block);
    s.placements.push_back({slot, name, 0});
  }
}

Expected<Scene> buildScene(const VoxFile& f, PlacedVoxels& placed, const VoxImportOptions& o,
                           VoxImportReport& report) {
  auto model_box = placed.box();
  if (!model_box) return model_box.status();
  if (o.ground) {
    if (Status st = addGround(*model_box, placed); !st) return st;
  }
  auto box = placed.box();
  if (!box) return box.status();
  const std::array<int, 3> lo = (*box)[0], hi = (*box)[1];
  Scene s;
  const std::array<int, 3> dims{hi[0] - lo[0] + 1, hi[2] - lo[2] + 1, hi[1] - lo[1] + 1};
  for (size_t a = 0; a < 3; ++a) s.size[a] = (dims[a] + 15) / 16;
  vox::MaterialNotes notes;
  std::map<uint8_t, uint8_t> palette_of;  // .vox colour index -> our palette index
  std::map<std::array<int, 3>, Block> blocks;
  glm::dvec3 box_lo(1e30), box_hi(-1e30);  // the models' solid voxels, in voxel units
  placed.forEach([&](const std::array<int, 3>& at, uint8_t colour) {
    auto [it, inserted] = palette_of.emplace(colour, uint8_t(palette_of.size() + 1));
    if (inserted && colour == kGroundColour) s.palette.push_back(kGroundEntry);
    if (inserted && colour != kGroundColour) {
      auto m = f.materials.find(colour);
      s.palette.push_back(vox::mapMaterial(
          colour, f.palette[colour], m == f.materials.end() ? nullptr : &m->second, o, notes));
    }
    const int x = at[0] - lo[0], y = at[1] - lo[1], z = at[2] - lo[2];
    const std::array<int, 3> p{x, z, dims[2] - 1 - y};
    for (int i = 0; i < 3 && colour != kGroundColour; ++i)
      box_lo[i] = std::min(box_lo[i], double(p[i])), box_hi[i] = std::max(box_hi[i], p[i] + 1.0);
    Block& b = blocks[{p[0] / 16, p[1] / 16, p[2] / 16}];
    uint8_t& cell = b.voxels[size_t((p[0] % 16) + 16 * (p[1] % 16) + 256 * (p[2] % 16))];
    (colour == kGroundColour ? report.ground_voxels : report.voxels) += cell == 0 ? 1 : 0;
    cell = it->second;
  });
  if (s.palette.size() > 255)
    return Status::error(".vox model uses more than 255 colours" +
                         std::string(o.ground ? " with the ground's" : ""));
  notes.finish(report);
  s.emission_scale = notes.emissionScale();
  for (const auto& [colour, slot] : palette_of) {
    const int emission = colour == kGroundColour ? -1 : notes.emissionLevel(colour);
    if (emission >= 0) s.palette[slot - 1u].emission = emission;
  }
  addBlocks(blocks, s);
  vox::mapLights(f, s, report.lights, report.dropped);
  s.cameras = vox::voxCameras(box_lo / 16.0, box_hi / 16.0, s.size, f, vox::WorldToScene{lo, hi},
                              report.cameras, report.dropped);
  return s;
}

// The shapes of `options.frame`: the scene graph's, else PACK model `frame` at the origin.
Expected<std::vector<Instance>> chooseInstances(const VoxFile& f, const VoxImportOptions& o,
                                                VoxImportReport& report) {
  report.frames = vox::frameCount(f, report.scene_graph);
  report.frame = o.frame;
  if (o.frame < 0 || o.frame >= report.frames)
    return Status::error(
        ".vox --frame " + std::to_string(o.frame) + ": the file has " +
        std::to_string(report.frames) + " animation frame" +
        (report.frames == 1 ? " (0)" : "s (0.." + std::to_string(report.frames - 1) + ")"));
  if (!report.scene_graph) return std::vector<Instance>{{o.frame, vox::Transform{}}};
  auto layers = vox::chooseLayers(f, o.layers);
  if (!layers) return layers.status();
  return vox::walkGraph(f, o.frame, *layers, report);
}

}  // namespace

Expected<Scene> importVox(const std::string& bytes, const VoxImportOptions& options,
                          VoxImportReport* report_out) {
  auto file = vox::parseVox(bytes);
  if (!file) return file.status();
  VoxImportReport report;
  report.models = int(file->models.size());
  report.materials = int(file->materials.size());
  report.default_palette = !file->has_rgba;
  report.scene_graph = file->nodes.count(0) > 0;
  if (!report.scene_graph && !options.layers.empty())
    return Status::error(".vox --layers: the file has no scene graph, so no layers");
  auto instances = chooseInstances(*file, options, report);
  if (!instances) return instances.status();
  report.instances = int(instances->size());
  if (report.hidden > 0)
    report.dropped.push_back(std::to_string(report.hidden) + " hidden shape" +
                             (report.hidden == 1 ? "" : "s") +
                             " (hidden node or layer; --layers includes a hidden layer)");
  PlacedVoxels placed{*file, *instances, report.scene_graph};
  auto scene = buildScene(*file, placed, options, report);
  if (!scene) return scene;
  vox::chooseBakeDefaults(*scene, report.chosen);
  if (Status s = validateScene(*scene); !s) return Status::error(".vox import: " + s.message());
  if (report_out) *report_out = std::move(report);
  return scene;
}

}  // namespace rdm
