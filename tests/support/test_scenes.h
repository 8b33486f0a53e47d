// Small scenes built in code for the transport and bake tests.
#pragma once

#include <algorithm>
#include <array>
#include <functional>
#include <string>

#include "rdm/scene/scene.h"

namespace rdm::test {

// Chess as JSON at `spp` with small RDMs and no face light: a daemon bake of a second or two.
inline std::string tinyChess(int spp = 1, int hemisphere = 4, int bounces = 1) {
  Scene s = *builtinScene("chess");
  s.bake.spp = spp, s.bake.max_hemisphere = hemisphere, s.bake.max_bounces = bounces;
  s.face_light_spp = 0;
  return sceneToJson(s);
}

// `scene` without its placement at slot `at` (chess's pawn at 5,1,2 in the rebake tests).
inline Scene withoutPlacementAt(Scene scene, std::array<int, 3> at) {
  auto& p = scene.placements;
  p.erase(std::remove_if(p.begin(), p.end(), [&](const Placement& q) { return q.at == at; }),
          p.end());
  return scene;
}

inline Block blockFrom(const std::function<int(int, int, int)>& fn) {
  Block b;
  for (int z = 0; z < 16; ++z)
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x) b.voxels[x + 16 * y + 256 * z] = uint8_t(fn(x, y, z));
  return b;
}

inline Scene uniformSkyScene(int sx, int sy, int sz, double sky = 1.0) {
  Scene s;
  s.size = {sx, sy, sz};
  s.palette = {{{255, 255, 255}, 7, 0, 0}};
  s.sky = Sky{glm::dvec3(sky), glm::dvec3(sky), glm::dvec3(sky)};
  s.bake = {16, 4, 7, 8};
  return s;
}

// A small scene with a wall, a mirror and a glossy block: every origin distribution runs.
inline Scene mixedScene() {
  Scene s = uniformSkyScene(3, 2, 3);
  s.palette = {{{255, 255, 255}, 7, 0, 0}, {{200, 200, 210}, 0, 3, 0}, {{180, 90, 60}, 3, 1, 0}};
  s.blocks["wall"] = blockFrom([](int x, int y, int) { return x < 4 || y < 3 ? 1 : 0; });
  s.blocks["mirror"] = blockFrom([](int x, int, int z) { return (x + z) % 3 ? 2 : 3; });
  s.placements = {{{1, 0, 1}, "wall", 0},
                  {{0, 0, 1}, "mirror", 0},
                  {{1, 1, 1}, "wall", 5},
                  {{2, 0, 0}, "mirror", 7}};
  s.bake = {4, 4, 3, 8};
  return s;
}

// Random voxels (density in [0, 1]) in every slot, deterministic in `seed`.
inline Scene randomVoxelScene(int sx, int sy, int sz, double density, uint32_t seed) {
  Scene s = uniformSkyScene(sx, sy, sz);
  uint32_t state = seed * 2654435761u + 1u;
  auto next = [&] {
    state ^= state << 13, state ^= state >> 17, state ^= state << 5;
    return double(state) / 4294967296.0;
  };
  for (int k = 0; k < sz; ++k)
    for (int j = 0; j < sy; ++j)
      for (int i = 0; i < sx; ++i) {
        if (next() < 0.3) continue;  // some empty slots exercise the slot-level skip
        std::string name =
            "b" + std::to_string(i) + "_" + std::to_string(j) + "_" + std::to_string(k);
        s.blocks[name] = blockFrom([&](int, int, int) { return next() < density ? 1 : 0; });
        s.placements.push_back({{i, j, k}, name, int(next() * 24) % 24});
      }
  return s;
}

}  // namespace rdm::test
