#include "block_shapes.h"

#include <cmath>
#include <cstdint>

namespace rdm::shapes {

Block makeBlock(const VoxelFn& fn) {
  Block block;
  for (int z = 0; z < 16; ++z)
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x) block.voxels[x + 16 * y + 256 * z] = uint8_t(fn(x, y, z));
  return block;
}

Block fillBlock(int index) {
  return makeBlock([=](int, int, int) { return index; });
}

Block latheBlock(const std::function<double(int)>& radius, int index) {
  return makeBlock([&](int x, int y, int z) {
    double dx = x + 0.5 - 8.0, dz = z + 0.5 - 8.0;
    double r = radius(y);
    return r > 0 && dx * dx + dz * dz <= r * r ? index : 0;
  });
}

Block sphereBlock(double radius, int index) {
  return makeBlock([=](int x, int y, int z) {
    double dx = x + 0.5 - 8, dy = y + 0.5 - 8, dz = z + 0.5 - 8;
    return dx * dx + dy * dy + dz * dz <= radius * radius ? index : 0;
  });
}

double pieceRadius(const std::string& kind, int y) {
  if (y < 2) return 6.0;  // base
  if (kind == "pawn") return y < 7 ? 3.0 : (y < 11 ? 4.0 - std::abs(y - 9) * 0.8 : 0.0);
  if (kind == "rook") return y < 11 ? 4.0 : (y < 13 ? 5.0 : 0.0);
  if (kind == "bishop") return y < 9 ? 3.0 : (y < 14 ? 4.0 - (y - 9) * 0.7 : (y < 15 ? 1.2 : 0.0));
  if (kind == "queen") return y < 12 ? 3.0 + (y > 9 ? 1.0 : 0.0) : (y < 15 ? 4.5 : 0.0);
  if (kind == "king") return y < 13 ? 3.2 : (y < 16 ? 1.5 : 0.0);
  return y < 8 ? 3.5 : (y < 13 ? 2.5 : 0.0);  // knight: a stepped column
}

Block lampBlock(int post, int light) {
  return makeBlock([=](int x, int y, int z) {
    bool is_post = y < 11 && x >= 7 && x < 9 && z >= 7 && z < 9;
    bool is_light = y >= 11 && y < 15 && x >= 6 && x < 10 && z >= 6 && z < 10;
    return is_light ? light : (is_post ? post : 0);
  });
}

}  // namespace rdm::shapes
