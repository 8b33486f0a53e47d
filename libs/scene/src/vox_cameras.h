// Cameras of an imported .vox model (vox_cameras.cpp).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "rdm/scene/scene.h"
#include "vox_parse.h"

namespace rdm::vox {

// Where MagicaVoxel world coordinates (voxel corners, z up) land in the scene: the placed
// voxels span lo..hi (inclusive voxel indices); the scene point, in blocks, is
// (x - lo.x, z - lo.z, hi.y + 1 - y) / 16.
struct WorldToScene {
  std::array<int, 3> lo{0, 0, 0}, hi{0, 0, 0};
  glm::dvec3 operator()(const glm::dvec3& world) const;
};

// Camera 0 "default" (three-quarter view from MagicaVoxel's front, the -Y side, which is the
// scene's +Z side), then "front", "back", "left", "right", "top" and "iso", each framing the
// solid voxels' box lo..hi (blocks); then the file's rCAM cameras as "file_<id>" where they
// convert. One line per camera added goes to `mapped`, one per reason for refusing an rCAM to
// `dropped`.
std::vector<Camera> voxCameras(glm::dvec3 lo, glm::dvec3 hi, const std::array<int, 3>& size,
                               const VoxFile& f, const WorldToScene& to_scene,
                               std::vector<std::string>& mapped, std::vector<std::string>& dropped);

}  // namespace rdm::vox
