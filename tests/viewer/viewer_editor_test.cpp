// The viewer's editing pieces, on the CPU: the scene editor (presets, brush, pick, add,
// remove, carve, undo/redo) and the camera controller. Built with the viewer only.
#include <gtest/gtest.h>

#ifdef RDM_VIEWER_BINARY
#include "camera.h"
#include "camera_controller.h"
#include "editor.h"
#include "rdm/bake/bake_prediction.h"
#include "rdm/scene/scene.h"
#include "rdm/scene/world.h"

namespace rdm::viewer {
namespace {

// The panel's quality presets go through the editor: the scene's settings change, every
// RDM is stale, and undo brings the scene's own settings back.
TEST(ViewerEditor, QualityPresetSetsBakeSettingsAndUndoes) {
  SceneEditor editor(builtinScene("chess").value());
  const BakeSettings own = editor.scene().bake;
  bool all = false;
  editor.takeChangedSlots(&all);
  const BakeSettings draft = withPreset(own, qualityPreset("draft").value());
  ASSERT_NE(draft, own);
  ASSERT_TRUE(editor.setBakeSettings(draft));
  EXPECT_FALSE(editor.setBakeSettings(draft));  // unchanged: nothing to rebake
  EXPECT_EQ(editor.scene().bake, draft);
  editor.takeChangedSlots(&all);
  EXPECT_TRUE(all);
  ASSERT_TRUE(editor.undo());
  EXPECT_EQ(editor.scene().bake, own);
}

// The carve/paint brush: every solid voxel within the radius changes, empty ones stay empty,
// untouched blocks keep their names, and a drag (continued stroke) is one undo step.
// A saved view joins the editor's scene (so the panel's "save" keeps it) without an undo
// step or a changed slot; a second camera of the same name replaces the first.
TEST(ViewerEditor, PutCameraAddsOrReplacesByNameWithoutAnEdit) {
  SceneEditor editor(builtinScene("chess").value());
  const size_t before = editor.scene().cameras.size();
  Camera view{{1.0, 2.0, 3.0}, {4.0, 1.0, 4.0}, 40.0, "view_0"};
  editor.putCamera(view);
  view.fov_deg = 30.0;
  editor.putCamera(view);
  ASSERT_EQ(editor.scene().cameras.size(), before + 1);
  EXPECT_EQ(editor.scene().cameras.back(), view);
  EXPECT_FALSE(editor.canUndo());
  bool all = true;
  EXPECT_TRUE(editor.takeChangedSlots(&all).empty());
  EXPECT_FALSE(all);
}

TEST(ViewerEditor, BrushPaintsSolidVoxelsWithinItsRadiusAndAStrokeIsOneUndo) {
  SceneEditor editor(builtinScene("chess").value());
  const Scene before = editor.scene();
  const glm::ivec3 top(24, 15, 24);  // tile (1, 0, 1), its top layer
  const VoxelWorld w0 = buildWorld(before);
  auto voxelAt = [](const VoxelWorld& w, const glm::ivec3& v) {
    const int32_t b = w.blockAt(v >> 4);
    const glm::ivec3 l = v & 15;
    return b < 0 ? uint8_t(0) : w.blocks[size_t(b)].voxels[size_t(l.x + 16 * l.y + 256 * l.z)];
  };
  ASSERT_NE(voxelAt(w0, top), 0);
  ASSERT_EQ(voxelAt(w0, top + glm::ivec3(0, 1, 0)), 0);  // air above the tile
  const uint8_t colour = uint8_t(before.palette.size());
  ASSERT_TRUE(editor.brushVoxels(top, 2, colour, false));
  const VoxelWorld w1 = buildWorld(editor.scene());
  int painted = 0;
  for (int dz = -3; dz <= 3; ++dz)
    for (int dy = -3; dy <= 3; ++dy)
      for (int dx = -3; dx <= 3; ++dx) {
        const glm::ivec3 v = top + glm::ivec3(dx, dy, dz);
        const bool inside = dx * dx + dy * dy + dz * dz <= 4;
        const uint8_t was = voxelAt(w0, v), now = voxelAt(w1, v);
        if (inside && was != 0) {
          EXPECT_EQ(now, colour) << dx << " " << dy << " " << dz;
          ++painted;
        } else {
          EXPECT_EQ(now, was) << dx << " " << dy << " " << dz;  // outside, or air
        }
      }
  EXPECT_GT(painted, 10);
  // The stroke goes on: carving next to it joins the same undo step.
  ASSERT_TRUE(editor.brushVoxels(top + glm::ivec3(3, 0, 0), 1, 0, true));
  EXPECT_EQ(voxelAt(buildWorld(editor.scene()), top + glm::ivec3(3, 0, 0)), 0);
  EXPECT_FALSE(editor.brushVoxels(top + glm::ivec3(0, 8, 0), 2, colour, true));  // all air
  ASSERT_TRUE(editor.undo());
  EXPECT_EQ(editor.scene().blocks, before.blocks);
  EXPECT_EQ(editor.scene().placements, before.placements);
  EXPECT_FALSE(editor.canUndo());
  EXPECT_FALSE(editor.brushVoxels(top, 9, colour, false));  // radius past the limit
}

TEST(ViewerEditor, PickAddRemoveCarveUndoRedo) {
  SceneEditor editor(builtinScene("chess").value());
  const size_t placements = editor.scene().placements.size();
  // Straight down onto tile (1, 0, 1): its top voxel layer, normal +Y.
  const Pick pick = pickVoxel(buildWorld(editor.scene()), {1.5f, 5.0f, 1.5f}, {0.0f, -1.0f, 0.0f});
  ASSERT_TRUE(pick.hit);
  EXPECT_EQ(pick.voxel, glm::ivec3(24, 15, 24));
  EXPECT_EQ(pick.slot, glm::ivec3(1, 0, 1));
  EXPECT_EQ(pick.normal, glm::ivec3(0, 1, 0));
  ASSERT_TRUE(editor.addBlock(pick.slot + pick.normal, "pawn_light", 5));
  EXPECT_FALSE(editor.addBlock(pick.slot + pick.normal, "pawn_light", 0));  // occupied
  EXPECT_EQ(editor.scene().placements.size(), placements + 1);
  ASSERT_TRUE(editor.removeBlock({1, 1, 1}));
  ASSERT_TRUE(editor.undo());
  EXPECT_EQ(editor.scene().placements.size(), placements + 1);
  ASSERT_TRUE(editor.redo());
  EXPECT_EQ(editor.scene().placements.size(), placements);
  // Paint one voxel of a rotated placement (dark pieces have rot 2): exactly that global
  // voxel changes; other slots using the same block keep it.
  const VoxelWorld before = buildWorld(editor.scene());
  glm::ivec3 target(-1);
  for (int v = 0; v < 4096 && target.x < 0; ++v) {
    const glm::ivec3 g = glm::ivec3(0, 1, 7) * 16 + glm::ivec3(v % 16, (v / 16) % 16, v / 256);
    if (before.voxelAt(g) == 4) target = g;
  }
  ASSERT_GE(target.x, 0);
  ASSERT_TRUE(editor.setVoxel(target, 1));
  const VoxelWorld after = buildWorld(editor.scene());
  int changed = 0;
  for (int z = 0; z < 128; ++z)
    for (int y = 0; y < 32; ++y)
      for (int x = 0; x < 128; ++x)
        changed += before.voxelAt({x, y, z}) != after.voxelAt({x, y, z});
  EXPECT_EQ(changed, 1);
  EXPECT_EQ(after.voxelAt(target), 1);
  bool all = true;
  EXPECT_FALSE(editor.takeChangedSlots(&all).empty());
  EXPECT_TRUE(all);  // undo/redo happened since the last take
  ASSERT_TRUE(editor.undo());
  EXPECT_EQ(buildWorld(editor.scene()).voxelAt(target), 4);
}

TEST(ViewerCameraController, OrbitKeepsTheSceneCameraAndNeverLooksAlongY) {
  const Camera start{{-2.0, 5.0, -2.0}, {4.0, 1.0, 4.0}, 50.0};
  CameraController controller;
  controller.reset(start);
  const Camera same = controller.camera();
  EXPECT_NEAR(glm::distance(glm::vec3(same.position), glm::vec3(start.position)), 0.0f, 1e-4f);
  EXPECT_NEAR(glm::distance(glm::vec3(same.target), glm::vec3(start.target)), 0.0f, 1e-4f);
  CameraInput in;
  in.rotate = {0.0f, -100000.0f};  // drag far past the pole
  controller.update(in);
  EXPECT_TRUE(cameraBasis(controller.camera()).ok());
  controller.setMode(CameraMode::kFly);
  in = CameraInput();
  in.move = {0.0f, 0.0f, 1.0f};
  in.dt = 0.5f;
  const glm::vec3 p0(controller.camera().position);
  controller.update(in);
  EXPECT_GT(glm::distance(glm::vec3(controller.camera().position), p0), 1.0f);
}

}  // namespace
}  // namespace rdm::viewer

#endif  // RDM_VIEWER_BINARY
