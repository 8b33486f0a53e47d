// The scene-graph walk of a .vox file (vox_graph.cpp): which models are placed where, at one
// animation frame, with the chosen layers.
#pragma once

#include <array>
#include <set>
#include <string>
#include <vector>

#include "rdm/scene/vox_import.h"
#include "vox_parse.h"

namespace rdm::vox {

// A rotation (integer matrix, rows) and translation, applied as R p + t.
struct Transform {
  std::array<std::array<int, 3>, 3> r{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  std::array<int, 3> t{0, 0, 0};
  std::array<int, 3> apply(const std::array<int, 3>& p) const;
  Transform then(const Transform& child) const;  // this * child
};

struct Instance {
  int model = 0;
  Transform transform;
};

// Animation frames of the file: 1 + the largest keyframe index of the scene graph; without
// one, the models (a PACK animation: model k is frame k).
int frameCount(const VoxFile& f, bool scene_graph);

// Layer ids that --layers names (by LAYR `_name` or index); the error lists the layers.
Expected<std::set<int>> chooseLayers(const VoxFile& f, const std::vector<std::string>& names);

// The shapes placed at `frame`: hidden nodes and hidden layers are left out (counted in
// report.hidden) unless the layer is in `shown`.
Expected<std::vector<Instance>> walkGraph(const VoxFile& f, int frame, const std::set<int>& shown,
                                          VoxImportReport& report);

}  // namespace rdm::vox
