// Import of MagicaVoxel .vox models (format version 150: SIZE, XYZI and RGBA chunks of the
// first model) as a scene: the model is cut into 16^3 blocks, one block per non-empty
// 16^3 cell. MagicaVoxel's +Z (up) becomes +Y; (x, y, z) maps to (x, z, size_y - 1 - y),
// a proper rotation, so models keep their handedness.
#pragma once

#include <string>

#include "rdm/scene.h"
#include "rdm/status.h"

namespace rdm {

struct VoxImportOptions {
  int roughness = 7;  // material of every imported colour
  int metallic = 0;
};

// Errors name the byte offset and chunk of malformed input.
Expected<Scene> importVox(const std::string& bytes, const VoxImportOptions& options = {});

}  // namespace rdm
