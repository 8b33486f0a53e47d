// Scene JSON fixtures shared by the scene loader tests: a valid base scene to mutate.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "rdm/base/base64.h"
#include "rdm/scene/scene.h"

namespace rdm::test {

using nlohmann::json;

// A small valid scene touching every section; the refusal cases each break one thing.
// Palette has 2 entries; "ball" has palette index 2 in a sphere and 1 elsewhere on the floor.
inline std::vector<uint8_t> ballVoxels() {
  std::vector<uint8_t> voxels(4096, 0);
  for (int z = 0; z < 16; ++z)
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x) {
        double dx = x - 7.5, dy = y - 7.5, dz = z - 7.5;
        if (dx * dx + dy * dy + dz * dz <= 36.0) voxels[x + 16 * y + 256 * z] = 2;
        if (y == 0) voxels[x + 16 * y + 256 * z] = 1;
      }
  return voxels;
}

inline json baseSceneJson() {
  return json{
      {"format", "rdm-scene"},
      {"version", 1},
      {"size", {4, 3, 4}},
      {"palette",
       {{{"color", {200, 60, 40}}, {"roughness", 0}, {"metallic", 3}, {"emission", 0}},
        {{"color", {10, 20, 30}}, {"emission", 2}}}},
      {"blocks", {{"stone", {{"fill", 1}}}, {"ball", {{"voxels", base64Encode(ballVoxels())}}}}},
      {"placements",
       {{{"at", {0, 0, 0}}, {"block", "stone"}, {"rot", 0}},
        {{"at", {1, 0, 0}}, {"block", "ball"}, {"rot", 5}},
        {{"at", {3, 2, 3}}, {"block", "ball"}}}},
      {"sun",
       {{"direction", {0.3, 1.0, 0.2}},
        {"irradiance", {3.0, 2.9, 2.7}},
        {"angular_radius_deg", 0.27}}},
      {"sky",
       {{"zenith", {0.3, 0.5, 0.9}}, {"horizon", {0.8, 0.85, 0.9}}, {"ground", {0.2, 0.18, 0.15}}}},
      {"emission_scale", 8.0},
      {"ambient", {0.2, 0.2, 0.25}},
      {"bake", {{"spp", 256}, {"max_bounces", 4}, {"seed", 1}, {"max_hemisphere", 256}}},
      {"cameras",
       {{{"position", {-2.0, 5.0, -2.0}}, {"target", {4.0, 1.0, 4.0}}, {"fov_deg", 50}}}},
  };
}

inline ::testing::AssertionResult refused(const std::string& text,
                                          const std::vector<std::string>& needles) {
  auto scene = parseSceneJson(text);
  if (scene.ok()) return ::testing::AssertionFailure() << "accepted";
  for (const std::string& needle : needles) {
    if (scene.error().find(needle) == std::string::npos) {
      return ::testing::AssertionFailure()
             << "message '" << scene.error() << "' lacks '" << needle << "'";
    }
  }
  return ::testing::AssertionSuccess() << scene.error();
}

}  // namespace rdm::test
