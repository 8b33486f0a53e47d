// Built-in scenes (docs/spec.md section 7), modelled on the thesis's test scenes. They are pure
// functions of their name: the same bytes every time.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "block_shapes.h"
#include "rdm/scene/scene.h"
#include "reflection_scenes.h"

namespace rdm {
namespace {

using shapes::fillBlock;
using shapes::latheBlock;
using shapes::makeBlock;
using shapes::pieceRadius;
using shapes::sphereBlock;

Scene chessScene() {
  Scene s;
  s.size = {8, 2, 8};
  s.palette = {
      {{235, 228, 215}, 1, 0, 0},  // 1 light tile, polished
      {{28, 28, 34}, 1, 0, 0},     // 2 dark tile, polished
      {{240, 236, 226}, 3, 0, 0},  // 3 light piece
      {{24, 22, 26}, 2, 0, 0},     // 4 dark piece
      {{212, 175, 55}, 2, 3, 0},   // 5 gold (crowns)
  };
  s.blocks["tile_light"] = fillBlock(1);
  s.blocks["tile_dark"] = fillBlock(2);
  const char* kinds[] = {"rook", "knight", "bishop", "queen", "king", "bishop", "knight", "rook"};
  for (int side = 0; side < 2; ++side) {
    int colour = side == 0 ? 3 : 4;
    for (const std::string kind : {"pawn", "rook", "knight", "bishop", "queen", "king"}) {
      Block b = latheBlock([&](int y) { return pieceRadius(kind, y); }, colour);
      if (kind == "king" || kind == "queen") {
        for (int x = 7; x < 9; ++x)
          for (int z = 7; z < 9; ++z) b.voxels[x + 16 * 15 + 256 * z] = 5;
      }
      s.blocks[kind + (side == 0 ? "_light" : "_dark")] = b;
    }
  }
  for (int k = 0; k < 8; ++k)
    for (int i = 0; i < 8; ++i)
      s.placements.push_back({{i, 0, k}, (i + k) % 2 ? "tile_light" : "tile_dark", 0});
  // Sixteen pieces: a back rank per side plus pawns in the middle files, as in a game.
  for (int i = 0; i < 8; ++i) {
    bool back = i % 2 == 0 || i == 3 || i == 4;
    std::string kind = back ? kinds[i] : "pawn";
    s.placements.push_back({{i, 1, back ? 0 : 2}, kind + "_light", 0});
    s.placements.push_back({{i, 1, back ? 7 : 5}, kind + "_dark", 2});
  }
  s.sun = Sun{{-0.5, 0.8, 0.35}, {3.0, 2.9, 2.7}, 0.27};
  s.sky = Sky{{0.25, 0.35, 0.6}, {0.6, 0.65, 0.7}, {0.15, 0.13, 0.12}};
  s.ambient = {0.35, 0.38, 0.45};
  s.bake = {4, 3, 1, 64};  // prefiltered: 6.5x lower noise than 16 spp naive (docs/results.md 2b)
  s.face_light_spp = 64;   // 29 % of the RDM bake (docs/results.md 1e)
  s.cameras = {{{-2.0, 5.0, -2.0}, {4.0, 1.0, 4.0}, 50.0},
               {{4.0, 3.2, -3.5}, {4.0, 1.0, 4.0}, 45.0}};
  return s;
}

double islandDistance(int i, int k) {
  return std::hypot(i + 0.5 - 7.0, k + 0.5 - 7.0);
}

Scene islandScene() {
  Scene s;
  s.size = {14, 5, 14};
  s.palette = {
      {{92, 140, 62}, 6, 0, 0},    // 1 grass
      {{122, 86, 56}, 7, 0, 0},    // 2 dirt
      {{128, 128, 128}, 5, 0, 0},  // 3 stone
      {{222, 202, 152}, 7, 0, 0},  // 4 sand
      {{232, 232, 236}, 0, 3, 0},  // 5 mirror metal
      {{230, 230, 230}, 2, 0, 0},  // 6 smooth white
      {{200, 60, 40}, 2, 0, 0},    // 7 smooth red
      {{255, 214, 150}, 7, 0, 3},  // 8 lamp
      {{110, 80, 50}, 6, 0, 0},    // 9 wood
  };
  s.blocks["ground"] = makeBlock([](int, int y, int) { return y >= 13 ? 1 : (y >= 6 ? 2 : 3); });
  s.blocks["ground_carved"] = makeBlock([](int x, int y, int z) {
    bool groove = y >= 12 && std::abs(2 * x - 15) <= 3;
    bool pit = y >= 10 && (x - 11) * (x - 11) + (z - 4) * (z - 4) <= 4;
    return groove || pit ? 0 : (y >= 13 ? 1 : (y >= 6 ? 2 : 3));
  });
  s.blocks["beach"] = makeBlock([](int x, int y, int z) {
    int h = 9 + int(2.0 * std::sin(x * 0.7) + 1.5 * std::cos(z * 0.9));
    return y <= h ? (y > 4 ? 4 : 3) : 0;
  });
  s.blocks["hill"] = makeBlock([](int x, int y, int z) {
    int h = 8 + int(3.0 * std::sin(x * 0.45 + 0.3) * std::cos(z * 0.5 - 0.2));
    return y < h ? (y + 3 >= h ? 1 : 2) : 0;
  });
  s.blocks["mirror"] = fillBlock(5);
  s.blocks["sphere_white"] = sphereBlock(7.2, 6);
  s.blocks["sphere_red"] = sphereBlock(6.5, 7);
  s.blocks["lamp"] = shapes::lampBlock(9, 8);
  auto occupied = [&](int i, int j, int k) {
    for (const Placement& p : s.placements) {
      if (p.at == std::array<int, 3>{i, j, k}) return true;
    }
    return false;
  };
  for (int k = 0; k < 14; ++k) {
    for (int i = 0; i < 14; ++i) {
      double d = islandDistance(i, k);
      if (d > 6.3) continue;
      std::string block =
          d > 5.4 ? "beach" : ((i * 7 + k * 3) % 5 == 0 ? "ground_carved" : "ground");
      s.placements.push_back({{i, 0, k}, block, (i + 2 * k) % 4});
      if (std::hypot(i + 0.5 - 9.5, k + 0.5 - 8.5) < 2.6)
        s.placements.push_back({{i, 1, k}, "hill", (i + k) % 4});
    }
  }
  for (int j = 1; j <= 2; ++j)
    for (int k = 4; k <= 5; ++k)
      for (int i = 3; i <= 4; ++i) s.placements.push_back({{i, j, k}, "mirror", 0});
  for (auto [i, j, k, name] : {std::tuple{6, 1, 4, "sphere_white"},
                               {4, 1, 8, "sphere_red"},
                               {9, 2, 8, "sphere_white"},
                               {7, 1, 10, "sphere_red"}}) {
    if (!occupied(i, j, k)) s.placements.push_back({{i, j, k}, name, 0});
  }
  for (auto [i, k] : {std::pair{2, 7}, {6, 2}, {11, 6}, {8, 11}}) {
    if (!occupied(i, 1, k)) s.placements.push_back({{i, 1, k}, "lamp", 0});
  }
  s.sun = Sun{{0.5, 0.9, -0.3}, {2.6, 2.5, 2.3}, 0.27};
  s.sky = Sky{{0.22, 0.38, 0.75}, {0.65, 0.72, 0.8}, {0.12, 0.11, 0.1}};
  s.emission_scale = 8.0;
  s.ambient = {0.3, 0.34, 0.42};
  // Prefiltered 4 spp (2.3x lower noise than 16 spp naive, docs/results.md 2b); S <= 128 keeps
  // the mirror cube sharp: 0.64 s instead of 0.11 s, live rebakes converge in 1.05 s instead
  // of 0.45 s (docs/results.md 1d).
  s.bake = {4, 3, 1, 128};
  s.face_light_spp = 8;  // 104,390 exposed faces: 32 % of the RDM bake (docs/results.md 1d)
  s.cameras = {{{-3.0, 6.0, -3.0}, {7.0, 1.0, 7.0}, 50.0},
               {{13.5, 4.0, 1.5}, {6.0, 1.5, 7.0}, 50.0}};
  return s;
}

// One white diffuse block under a uniform white sky: the white-furnace scene.
Scene furnaceScene() {
  Scene s;
  s.size = {3, 3, 3};
  s.palette = {{{255, 255, 255}, 7, 0, 0}};
  s.blocks["white"] = fillBlock(1);
  s.placements = {{{1, 1, 1}, "white", 0}};
  s.sky = Sky{{1, 1, 1}, {1, 1, 1}, {1, 1, 1}};
  s.ambient = {1, 1, 1};
  s.bake = {64, 4, 1, 8};
  s.face_light_spp = 64;
  s.cameras = {{{-2.0, 3.0, -2.5}, {1.5, 1.5, 1.5}, 50.0}};
  return s;
}

// Deterministic integer generator for the terrain's boxes (portable, unlike std
// distributions): splitmix64.
struct SplitMix {
  uint64_t state;
  uint32_t next() {
    uint64_t z = (state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return uint32_t((z ^ (z >> 31)) >> 32);
  }
  int range(int lo, int hi) { return lo + int(next() % uint32_t(hi - lo + 1)); }  // [lo, hi]
};

// Solid voxels per terrain column: y < h(x, z) (voxel units).
int terrainColumn(int x, int z) {
  double h =
      18.0 + 7.0 * std::sin(0.045 * x) * std::cos(0.061 * z) + 4.0 * std::sin(0.13 * x + 0.09 * z);
  return int(std::ceil(h));
}

// A dense world for traversal benchmarks (docs/performance.md): 256 x 64 x 256 voxels of
// terrain with 60 boxes standing on it, half of them hollow (walls and a roof).
Scene terrainScene() {
  constexpr int kW = 256, kH = 64;
  std::vector<uint8_t> grid(size_t(kW) * kH * kW, 0);
  auto at = [&](int x, int y, int z) -> uint8_t& { return grid[x + kW * (y + kH * size_t(z))]; };
  for (int z = 0; z < kW; ++z)
    for (int x = 0; x < kW; ++x) {
      int top = terrainColumn(x, z);
      for (int y = 0; y < std::min(top, kH); ++y)
        at(x, y, z) = y + 1 >= top ? 1 : (y + 4 >= top ? 2 : 3);
    }
  SplitMix rng{0x7e44a1};
  for (int i = 0; i < 60; ++i) {
    int wx = rng.range(4, 15), wz = rng.range(4, 15), height = rng.range(4, 23);
    int x0 = rng.range(0, kW - wx), z0 = rng.range(0, kW - wz);
    bool hollow = i % 2 == 1;
    int base = kH;
    for (int z = z0; z < z0 + wz; ++z)
      for (int x = x0; x < x0 + wx; ++x) base = std::min(base, terrainColumn(x, z));
    int top = std::min(base + height, kH) - 1;
    uint8_t index = uint8_t(4 + i % 2);
    for (int z = z0; z < z0 + wz; ++z)
      for (int y = base; y <= top; ++y)
        for (int x = x0; x < x0 + wx; ++x) {
          bool wall = x == x0 || x == x0 + wx - 1 || z == z0 || z == z0 + wz - 1 || y == top;
          if (!hollow || wall) at(x, y, z) = index;
        }
  }
  Scene s;
  s.size = {kW / 16, kH / 16, kW / 16};
  s.palette = {
      {{92, 140, 62}, 6, 0, 0},    // 1 grass
      {{122, 86, 56}, 7, 0, 0},    // 2 dirt
      {{128, 128, 128}, 5, 0, 0},  // 3 stone
      {{225, 222, 214}, 4, 0, 0},  // 4 plaster (solid boxes)
      {{168, 74, 52}, 6, 0, 0},    // 5 brick (hollow boxes)
  };
  for (int k = 0; k < s.size[2]; ++k)
    for (int j = 0; j < s.size[1]; ++j)
      for (int i = 0; i < s.size[0]; ++i) {
        Block b =
            makeBlock([&](int x, int y, int z) { return at(16 * i + x, 16 * j + y, 16 * k + z); });
        if (std::all_of(b.voxels.begin(), b.voxels.end(), [](uint8_t v) { return v == 0; }))
          continue;
        std::string name = std::to_string(i) + "_" + std::to_string(j) + "_" + std::to_string(k);
        s.blocks[name] = std::move(b);
        s.placements.push_back({{i, j, k}, name, 0});
      }
  s.sun = Sun{{0.45, 0.8, 0.3}, {2.8, 2.7, 2.5}, 0.27};
  s.sky = Sky{{0.22, 0.38, 0.75}, {0.65, 0.72, 0.8}, {0.12, 0.11, 0.1}};
  s.ambient = {0.3, 0.34, 0.42};
  s.bake = {16, 3, 1, 16};
  s.face_light_spp = 4;  // 221,310 exposed faces: 27 % of the RDM bake (docs/results.md 1e)
  s.cameras = {{{-0.5, 3.0, 8.0}, {16.0, 1.2, 8.0}, 60.0},
               {{-1.0, 5.0, -1.0}, {9.0, 1.0, 9.0}, 55.0}};
  return s;
}

// Objects standing on a mirror floor inside the floor's own block (docs/results.md section 1b):
// everything between the floor (voxel layer 3) and the block's top face lies behind the RDM's
// face origin, so only a march through the block's voxels can reflect it.
Scene mirrorFloorScene() {
  Scene s;
  s.size = {3, 1, 3};
  s.palette = {
      {{232, 232, 236}, 0, 3, 0},  // 1 mirror metal
      {{40, 80, 200}, 5, 0, 0},    // 2 blue
      {{200, 50, 40}, 4, 0, 0},    // 3 red
      {{225, 222, 214}, 6, 0, 0},  // 4 plaster
  };
  auto mirror_layer = [](int y) { return y < 3; };
  s.blocks["floor"] = makeBlock([&](int, int y, int) { return mirror_layer(y) ? 1 : 0; });
  s.blocks["wall"] =
      makeBlock([&](int, int y, int z) { return mirror_layer(y) ? 1 : (z >= 13 ? 4 : 0); });
  s.blocks["exhibit"] = makeBlock([&](int x, int y, int z) {
    if (mirror_layer(y)) return 1;
    bool bar = x >= 3 && x < 5 && z >= 4 && z < 12 && y < 12;
    bool stem = x >= 9 && x < 11 && z >= 9 && z < 11 && y < 14;  // an "L"
    bool foot = x >= 9 && x < 14 && z >= 9 && z < 11 && y < 5;
    return bar ? 2 : (stem || foot ? 3 : 0);
  });
  for (int k = 0; k < 3; ++k)
    for (int i = 0; i < 3; ++i)
      s.placements.push_back(
          {{i, 0, k}, i == 1 && k == 1 ? "exhibit" : (k == 2 ? "wall" : "floor"), 0});
  s.sun = Sun{{-0.4, 0.8, -0.45}, {2.8, 2.7, 2.5}, 0.27};
  s.sky = Sky{{0.22, 0.38, 0.75}, {0.65, 0.72, 0.8}, {0.12, 0.11, 0.1}};
  s.ambient = {0.3, 0.34, 0.42};
  s.bake = {4, 3, 1, 128};
  s.face_light_spp = 64;  // 9 % of the RDM bake (docs/results.md 1e)
  s.cameras = {{{1.0, 0.75, -0.2}, {1.5, 0.2, 1.6}, 50.0}};
  return s;
}
}  // namespace

std::vector<std::string> builtinSceneNames() {
  return {"chess",       "island",          "furnace",    "terrain",    "mirror_floor",
          "mirror_lamp", "mirror_corridor", "mirror_row", "dark_pieces"};
}

Expected<Scene> builtinScene(const std::string& name) {
  if (name == "chess") return chessScene();
  if (name == "island") return islandScene();
  if (name == "furnace") return furnaceScene();
  if (name == "terrain") return terrainScene();
  if (name == "mirror_floor") return mirrorFloorScene();
  if (name == "mirror_lamp") return mirrorLampScene();
  if (name == "mirror_corridor") return mirrorCorridorScene();
  if (name == "mirror_row") return mirrorRowScene();
  if (name == "dark_pieces") return darkPiecesScene();
  return Status::error("unknown built-in scene '" + name + "' (known: " + builtinSceneList() + ")");
}

}  // namespace rdm
