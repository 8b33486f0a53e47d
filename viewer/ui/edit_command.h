// One scripted edit (`rdm-viewer --edit`, docs/viewer.md "Scripted edits"):
//   remove I,J,K                 empty slot (I, J, K)
//   add I,J,K BLOCK [ROT]        place BLOCK (orientation ROT, default 0) into an empty slot
//   paint I,J,K X,Y,Z PALETTE    set voxel (X, Y, Z) of the slot's block to PALETTE (0 carves)
#pragma once

#include <string>

#include <glm/glm.hpp>

#include "editor.h"
#include "rdm/base/status.h"

namespace rdm::viewer {

struct EditCommand {
  enum class Kind { kRemove, kAdd, kPaint } kind = Kind::kRemove;
  glm::ivec3 slot{0};
  std::string block;
  int rot = 0;
  glm::ivec3 voxel{0};  // within the slot, 0..15
  int palette = 0;
};

Expected<EditCommand> parseEditCommand(const std::string& text);
// Applies the edit through the editor; fails, naming why, when it does not apply.
Status applyEditCommand(const EditCommand& edit, SceneEditor& editor);

}  // namespace rdm::viewer
