// Scene editing for the window: picking with the core voxel traversal, adding/removing
// blocks, carving/painting voxels, palette edits, undo/redo. Pure CPU, no Vulkan.
#pragma once

#include <array>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "rdm/scene/scene.h"
#include "rdm/scene/world.h"

namespace rdm::viewer {

struct Pick {
  bool hit = false;
  glm::ivec3 voxel{0};  // global voxel coordinates
  glm::ivec3 slot{0};
  glm::ivec3 normal{0};  // outward normal of the face the ray entered through
};

// First solid voxel along the world-space ray (origin in world units, any direction).
Pick pickVoxel(const VoxelWorld& world, const glm::vec3& origin, const glm::vec3& direction);

class SceneEditor {
 public:
  explicit SceneEditor(Scene scene) : scene_(std::move(scene)) {}
  const Scene& scene() const { return scene_; }

  // Each edit returns false (and changes nothing) when it does not apply.
  bool addBlock(const glm::ivec3& slot, const std::string& block, int rot);
  bool removeBlock(const glm::ivec3& slot);
  // Sets one global voxel to palette index `palette` (0 carves). The slot's block becomes
  // a block of its own (`edit_i_j_k`, rot 0, voxels in slot space), so other slots sharing
  // the original block keep it.
  bool setVoxel(const glm::ivec3& voxel, uint8_t palette);
  // A brush: the solid voxels of placed blocks within `radius` voxels (Euclidean, 0..8) of
  // `center`, recoloured to `palette`, or carved when `palette` is 0; empty voxels stay
  // empty. With `continue_stroke` the change joins the previous edit's undo step, so one
  // drag is one undo.
  bool brushVoxels(const glm::ivec3& center, int radius, uint8_t palette, bool continue_stroke);
  bool setPaletteEntry(int index, const PaletteEntry& entry);  // index 1..
  int addPaletteEntry(const PaletteEntry& entry);              // new index, or 0 when full
  void replaceScene(Scene scene);                              // e.g. after loading a file
  // Adds `camera`, or replaces the one of its name; no undo step, no changed slot (a camera
  // lights nothing).
  void putCamera(const Camera& camera);
  // The scene's bake settings (a quality preset from the panel); every RDM changes with them.
  bool setBakeSettings(const BakeSettings& settings);

  bool undo();
  bool redo();
  bool canUndo() const { return !undo_.empty(); }
  bool canRedo() const { return !redo_.empty(); }
  // Slots changed since the last call (for incremental rebakes); `all` when global state changed.
  std::vector<glm::ivec3> takeChangedSlots(bool* all);

 private:
  void snapshot();
  // Writes edited slot-space blocks as the slots' own blocks (`edit_i_j_k`, rot 0).
  void commitBlocks(const std::map<std::array<int, 3>, Block>& edited);
  int placementAt(const glm::ivec3& slot) const;
  // Voxel `voxel` (world voxel coordinates) of `edited`; on first touch its slot's block is
  // copied in, in slot space as the world compiles it. nullptr for an empty or outside slot.
  uint8_t* editedVoxel(std::map<std::array<int, 3>, Block>& edited, const glm::ivec3& voxel) const;
  bool inGrid(const glm::ivec3& slot) const;

  Scene scene_;
  std::vector<Scene> undo_, redo_;
  std::set<std::array<int, 3>> changed_;
  bool all_changed_ = false;
};

}  // namespace rdm::viewer
