#include "editor.h"

#include <algorithm>

#include "rdm/trace/traversal.h"

namespace rdm::viewer {
namespace {

constexpr size_t kMaxUndo = 64;

}  // namespace

Pick pickVoxel(const VoxelWorld& world, const glm::vec3& origin, const glm::vec3& direction) {
  Pick pick;
  const FloatRay ray(origin * 16.0f, direction);
  float t_hit = 0.0f;
  const TraceHit hit = traceVoxels(world, ray, t_hit);
  if (!hit.hit || hit.axis < 0) return pick;
  pick.hit = true;
  pick.voxel = hit.voxel;
  pick.slot = hit.voxel >> 4;
  pick.normal[hit.axis] = direction[hit.axis] > 0.0f ? -1 : 1;
  return pick;
}

bool SceneEditor::inGrid(const glm::ivec3& s) const {
  return s.x >= 0 && s.y >= 0 && s.z >= 0 && s.x < scene_.size[0] && s.y < scene_.size[1] &&
         s.z < scene_.size[2];
}

int SceneEditor::placementAt(const glm::ivec3& slot) const {
  for (size_t i = 0; i < scene_.placements.size(); ++i) {
    if (scene_.placements[i].at == std::array<int, 3>{slot.x, slot.y, slot.z}) return int(i);
  }
  return -1;
}

void SceneEditor::snapshot() {
  undo_.push_back(scene_);
  if (undo_.size() > kMaxUndo) undo_.erase(undo_.begin());
  redo_.clear();
}

bool SceneEditor::addBlock(const glm::ivec3& slot, const std::string& block, int rot) {
  if (!inGrid(slot) || placementAt(slot) >= 0 || !scene_.blocks.count(block) || rot < 0 || rot > 23)
    return false;
  snapshot();
  scene_.placements.push_back({{slot.x, slot.y, slot.z}, block, rot});
  changed_.insert({slot.x, slot.y, slot.z});
  return true;
}

bool SceneEditor::setBakeSettings(const BakeSettings& settings) {
  if (settings == scene_.bake) return false;
  snapshot();
  scene_.bake = settings;
  all_changed_ = true;
  return true;
}

bool SceneEditor::removeBlock(const glm::ivec3& slot) {
  const int p = placementAt(slot);
  if (p < 0) return false;
  snapshot();
  scene_.placements.erase(scene_.placements.begin() + p);
  changed_.insert({slot.x, slot.y, slot.z});
  return true;
}

uint8_t* SceneEditor::editedVoxel(std::map<std::array<int, 3>, Block>& edited,
                                  const glm::ivec3& voxel) const {
  const glm::ivec3 slot = voxel >> 4, l = voxel & 15;
  const std::array<int, 3> key = {slot.x, slot.y, slot.z};
  auto it = edited.find(key);
  if (it == edited.end()) {
    const int p = inGrid(slot) ? placementAt(slot) : -1;
    if (p < 0) return nullptr;
    const Placement& placement = scene_.placements[size_t(p)];
    const auto block = scene_.blocks.find(placement.block);
    if (block == scene_.blocks.end()) return nullptr;
    const auto oriented = orientedVoxels(block->second, placement.rot);
    it = edited.emplace(key, Block{}).first;
    it->second.voxels.assign(oriented.begin(), oriented.end());
  }
  return &it->second.voxels[size_t(l.x + 16 * l.y + 256 * l.z)];
}

void SceneEditor::commitBlocks(const std::map<std::array<int, 3>, Block>& edited) {
  for (const auto& [key, block] : edited) {
    const glm::ivec3 slot(key[0], key[1], key[2]);
    const std::string name = "edit_" + std::to_string(slot.x) + "_" + std::to_string(slot.y) + "_" +
                             std::to_string(slot.z);
    scene_.blocks[name] = block;
    Placement& p = scene_.placements[size_t(placementAt(slot))];
    p.block = name, p.rot = 0;
    changed_.insert(key);
  }
  // Drop edit blocks no placement uses any more.
  for (auto it = scene_.blocks.begin(); it != scene_.blocks.end();) {
    const bool used = std::any_of(scene_.placements.begin(), scene_.placements.end(),
                                  [&](const Placement& q) { return q.block == it->first; });
    it = (!used && it->first.rfind("edit_", 0) == 0) ? scene_.blocks.erase(it) : std::next(it);
  }
}

bool SceneEditor::setVoxel(const glm::ivec3& voxel, uint8_t palette) {
  if (palette > scene_.palette.size()) return false;
  std::map<std::array<int, 3>, Block> edited;
  uint8_t* v = editedVoxel(edited, voxel);
  if (!v || *v == palette) return false;
  snapshot();
  *v = palette;
  commitBlocks(edited);
  return true;
}

bool SceneEditor::brushVoxels(const glm::ivec3& center, int radius, uint8_t palette,
                              bool continue_stroke) {
  if (radius < 0 || radius > 8 || palette > scene_.palette.size()) return false;
  std::map<std::array<int, 3>, Block> edited;
  std::set<std::array<int, 3>> changed;  // blocks read but left as they were are not edits
  for (int dz = -radius; dz <= radius; ++dz)
    for (int dy = -radius; dy <= radius; ++dy)
      for (int dx = -radius; dx <= radius; ++dx) {
        if (dx * dx + dy * dy + dz * dz > radius * radius) continue;
        const glm::ivec3 voxel = center + glm::ivec3(dx, dy, dz);
        uint8_t* v = editedVoxel(edited, voxel);
        if (!v || *v == 0 || *v == palette) continue;
        *v = palette;
        const glm::ivec3 slot = voxel >> 4;
        changed.insert({slot.x, slot.y, slot.z});
      }
  if (changed.empty()) return false;
  for (auto it = edited.begin(); it != edited.end();)
    it = changed.count(it->first) ? std::next(it) : edited.erase(it);
  if (continue_stroke && !undo_.empty()) {
    redo_.clear();
  } else {
    snapshot();
  }
  commitBlocks(edited);
  return true;
}

bool SceneEditor::setPaletteEntry(int index, const PaletteEntry& entry) {
  if (index < 1 || index > int(scene_.palette.size()) || scene_.palette[index - 1] == entry)
    return false;
  snapshot();
  scene_.palette[index - 1] = entry;
  all_changed_ = true;
  return true;
}

int SceneEditor::addPaletteEntry(const PaletteEntry& entry) {
  if (scene_.palette.size() >= 255) return 0;
  snapshot();
  scene_.palette.push_back(entry);
  return int(scene_.palette.size());
}

void SceneEditor::replaceScene(Scene scene) {
  snapshot();
  scene_ = std::move(scene);
  all_changed_ = true;
}

void SceneEditor::putCamera(const Camera& camera) {
  for (Camera& c : scene_.cameras) {
    if (!camera.name.empty() && c.name == camera.name) {
      c = camera;
      return;
    }
  }
  scene_.cameras.push_back(camera);
}

bool SceneEditor::undo() {
  if (undo_.empty()) return false;
  redo_.push_back(std::move(scene_));
  scene_ = std::move(undo_.back());
  undo_.pop_back();
  all_changed_ = true;
  return true;
}

bool SceneEditor::redo() {
  if (redo_.empty()) return false;
  undo_.push_back(std::move(scene_));
  scene_ = std::move(redo_.back());
  redo_.pop_back();
  all_changed_ = true;
  return true;
}

std::vector<glm::ivec3> SceneEditor::takeChangedSlots(bool* all) {
  std::vector<glm::ivec3> out;
  for (const auto& s : changed_) out.push_back({s[0], s[1], s[2]});
  if (all) *all = all_changed_;
  changed_.clear();
  all_changed_ = false;
  return out;
}

}  // namespace rdm::viewer
