// Block shapes the built-in scenes are made of (internal to the scene part): pure functions,
// the same bytes every time.
#pragma once

#include <functional>
#include <string>

#include "rdm/scene/scene.h"

namespace rdm::shapes {

// The palette index of voxel (x, y, z) of a block, 0 = empty.
using VoxelFn = std::function<int(int x, int y, int z)>;

Block makeBlock(const VoxelFn& fn);
Block fillBlock(int index);
// A body of revolution about the block's vertical axis: radius(y) in voxels, 0 = none.
Block latheBlock(const std::function<double(int)>& radius, int index);
Block sphereBlock(double radius, int index);
// The radius (voxels) at layer y of a chess piece of `kind` (pawn, rook, knight, bishop, queen,
// king), for latheBlock.
double pieceRadius(const std::string& kind, int y);
// An island lamp: a 2 x 2 post of `post` under a 4 x 4 x 4 head of `light`.
Block lampBlock(int post, int light);

}  // namespace rdm::shapes
