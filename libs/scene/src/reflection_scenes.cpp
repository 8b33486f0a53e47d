// Scenes for reflections close up (docs/spec.md section 7): each puts what a block-centred RDM
// sees from the wrong place right beside a reflecting surface. Pure functions of their names.
#include "reflection_scenes.h"

#include <string>

#include "block_shapes.h"

namespace rdm {
namespace {

using shapes::fillBlock;
using shapes::makeBlock;

// Island's daylight: sun, sky and ambient.
void daylight(Scene& s) {
  s.sun = Sun{{0.5, 0.9, -0.3}, {2.6, 2.5, 2.3}, 0.27};
  s.sky = Sky{{0.22, 0.38, 0.75}, {0.65, 0.72, 0.8}, {0.12, 0.11, 0.1}};
  s.ambient = {0.3, 0.34, 0.42};
}

// A floor block of 4 x 4-voxel squares of palette indices a and b: a pattern a reflection
// shows, with a top layer of those and index c below.
Block checkerFloor(int a, int b, int c) {
  return makeBlock([=](int x, int y, int z) {
    if (y < 15) return c;
    return ((x >> 2) + (z >> 2)) % 2 ? a : b;
  });
}

void fillLayer(Scene& s, int j, const std::string& block) {
  for (int k = 0; k < s.size[2]; ++k)
    for (int i = 0; i < s.size[0]; ++i) s.placements.push_back({{i, j, k}, block, 0});
}

}  // namespace

// A lamp half a block in front of a mirror wall: from the wall's RDM origin the lamp fills a
// wide cone it does not fill from most of the wall (issue 39, island's mirror cube).
Scene mirrorLampScene() {
  Scene s;
  s.size = {4, 3, 3};
  s.palette = {
      {{232, 232, 236}, 0, 3, 0},  // 1 mirror metal
      {{170, 160, 140}, 6, 0, 0},  // 2 light stone
      {{90, 110, 70}, 6, 0, 0},    // 3 moss
      {{110, 80, 50}, 6, 0, 0},    // 4 wood
      {{255, 214, 150}, 7, 0, 3},  // 5 lamp
  };
  s.blocks["floor"] = checkerFloor(2, 3, 2);
  s.blocks["mirror"] = fillBlock(1);
  s.blocks["lamp"] = shapes::lampBlock(4, 5);
  fillLayer(s, 0, "floor");
  for (int j = 1; j <= 2; ++j)
    for (int i = 0; i < 4; ++i) s.placements.push_back({{i, j, 2}, "mirror", 0});
  s.placements.push_back({{1, 1, 1}, "lamp", 0});
  daylight(s);
  s.emission_scale = 8.0;
  s.bake = {4, 3, 1, 128};
  s.face_light_spp = 64;
  s.cameras = {{{0.7, 1.8, -0.4}, {2.2, 1.6, 2.0}, 55.0}};
  return s;
}

// Mirror walls facing each other across a patterned floor, a red pillar between them: every
// reflection is of something within a few blocks, seen again in the opposite mirror.
Scene mirrorCorridorScene() {
  Scene s;
  s.size = {3, 2, 6};
  s.palette = {
      {{232, 232, 236}, 0, 3, 0},  // 1 mirror metal
      {{225, 222, 214}, 6, 0, 0},  // 2 plaster
      {{60, 70, 110}, 5, 0, 0},    // 3 slate blue
      {{200, 50, 40}, 4, 0, 0},    // 4 red
  };
  s.blocks["floor"] = checkerFloor(2, 3, 2);
  s.blocks["mirror"] = fillBlock(1);
  s.blocks["pillar"] = shapes::latheBlock([](int) { return 3.0; }, 4);
  fillLayer(s, 0, "floor");
  for (int k = 0; k < 6; ++k) {
    s.placements.push_back({{0, 1, k}, "mirror", 0});
    s.placements.push_back({{2, 1, k}, "mirror", 0});
  }
  s.placements.push_back({{1, 1, 3}, "pillar", 0});
  daylight(s);
  s.sun = Sun{{0.2, 0.9, 0.35}, {2.6, 2.5, 2.3}, 0.27};  // high, so the corridor is sun-lit
  // Paths of 8 bounces: the reference shows the pillar's fourth image, not black.
  s.bake = {4, 8, 1, 128};
  s.face_light_spp = 64;
  s.cameras = {{{1.5, 1.6, 0.15}, {1.5, 1.15, 6.0}, 60.0}};
  return s;
}

// Mirror blocks side by side under a row of brushed-metal blocks, spheres in front: where one
// block's RDM hands over to the next.
Scene mirrorRowScene() {
  Scene s;
  s.size = {6, 3, 3};
  s.palette = {
      {{232, 232, 236}, 0, 3, 0},  // 1 mirror metal
      {{200, 200, 205}, 2, 3, 0},  // 2 brushed metal
      {{225, 222, 214}, 6, 0, 0},  // 3 plaster
      {{60, 70, 110}, 5, 0, 0},    // 4 slate blue
      {{200, 60, 40}, 2, 0, 0},    // 5 smooth red
      {{230, 230, 230}, 2, 0, 0},  // 6 smooth white
  };
  s.blocks["floor"] = checkerFloor(3, 4, 3);
  s.blocks["mirror"] = fillBlock(1);
  s.blocks["brushed"] = fillBlock(2);
  s.blocks["sphere_red"] = shapes::sphereBlock(6.5, 5);
  s.blocks["sphere_white"] = shapes::sphereBlock(7.2, 6);
  fillLayer(s, 0, "floor");
  for (int i = 1; i <= 4; ++i) {
    s.placements.push_back({{i, 1, 2}, "mirror", 0});
    s.placements.push_back({{i, 2, 2}, "brushed", 0});
  }
  s.placements.push_back({{2, 1, 1}, "sphere_red", 0});
  s.placements.push_back({{4, 1, 0}, "sphere_white", 0});
  daylight(s);
  s.bake = {4, 3, 1, 128};
  s.face_light_spp = 64;
  s.cameras = {{{0.3, 1.7, -0.6}, {3.5, 1.45, 2.0}, 55.0}};
  return s;
}

// Dark glossy pieces on a dark polished floor, one light piece among them (chess's darkest
// residual: docs/results.md section 1g).
Scene darkPiecesScene() {
  Scene s;
  s.size = {4, 2, 4};
  s.palette = {
      {{28, 28, 34}, 1, 0, 0},     // 1 dark tile, polished
      {{52, 50, 60}, 1, 0, 0},     // 2 dark grey tile, polished
      {{24, 22, 26}, 2, 0, 0},     // 3 dark piece
      {{240, 236, 226}, 3, 0, 0},  // 4 light piece
  };
  s.blocks["tile_dark"] = fillBlock(1);
  s.blocks["tile_grey"] = fillBlock(2);
  for (int k = 0; k < 4; ++k)
    for (int i = 0; i < 4; ++i)
      s.placements.push_back({{i, 0, k}, (i + k) % 2 ? "tile_grey" : "tile_dark", 0});
  for (const std::string kind : {"rook", "pawn", "queen"}) {
    s.blocks[kind] = shapes::latheBlock([&](int y) { return shapes::pieceRadius(kind, y); }, 3);
  }
  s.blocks["bishop_light"] =
      shapes::latheBlock([](int y) { return shapes::pieceRadius("bishop", y); }, 4);
  s.placements.push_back({{1, 1, 1}, "rook", 0});
  s.placements.push_back({{2, 1, 2}, "pawn", 0});
  s.placements.push_back({{1, 1, 3}, "queen", 0});
  s.placements.push_back({{3, 1, 1}, "bishop_light", 0});
  s.sun = Sun{{-0.5, 0.8, 0.35}, {3.0, 2.9, 2.7}, 0.27};  // chess's light
  s.sky = Sky{{0.25, 0.35, 0.6}, {0.6, 0.65, 0.7}, {0.15, 0.13, 0.12}};
  s.ambient = {0.35, 0.38, 0.45};
  s.bake = {4, 3, 1, 64};
  s.face_light_spp = 64;
  s.cameras = {{{-0.8, 2.6, -0.8}, {2.0, 1.1, 2.0}, 45.0}};
  return s;
}

}  // namespace rdm
