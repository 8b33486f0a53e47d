// rdm-viewer in a real window under Xvfb, every frame forced to take at least 0.8 s
// (--min-frame-ms 800, as long as a lavapipe frame can take), driven through XTest by
// xdotool: a 0.1 s click with the remove tool removes the block under it, a 0.1 s Ctrl+Z tap
// undoes that, a 0.1 s click on a blank spot of the status bar removes nothing (ImGui's
// window covers the block behind it), and a 0.1 s click on the status bar's "bake in-process"
// button reaches Dear ImGui (the bake starts). Input polled once per frame loses a press and
// its release that both fall between two frames; the window queues them
// (viewer/app/input_queue.h). The test follows the viewer's stdout: one "edit: ..." line per
// applied edit, one "live: ..." line per applied bake update.
#include <gtest/gtest.h>

#ifdef RDM_VIEWER_BINARY
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "camera_controller.h"
#include "editor.h"
#include "fresh_dir.h"
#include "rdm/bake/render.h"
#include "rdm/base/file_util.h"
#include "rdm/scene/scene.h"
#include "rdm/scene/world.h"
#include "test_requirements.h"
#include "window_process.h"

namespace rdm::viewer {
namespace {

constexpr int kWidth = 960, kHeight = 540;  // the panel leaves the right half to the 3D view
constexpr int kMinFrameMs = 800;
constexpr double kWaitSeconds = 60.0;  // per step; a passing run takes a few frames

using window_test::Child;
using window_test::fileText;
using window_test::shell;
using window_test::Xvfb;

size_t occurrences(const std::string& text, const std::string& needle) {
  size_t n = 0;
  for (size_t at = text.find(needle); at != std::string::npos; at = text.find(needle, at + 1)) ++n;
  return n;
}

// The file's text once `needle` occurs in it, or what it holds after kWaitSeconds or once
// `viewer` ended.
std::string waitForLine(const std::string& path, const std::string& needle, Child& viewer) {
  return window_test::waitForLine(path, needle, viewer, kWaitSeconds);
}

// What a left click at window pixel (x, y) picks: the viewer's own pick (WindowApp::pickAt)
// with the scene camera as the window starts.
Pick pickAt(const VoxelWorld& world, const Camera& camera, int x, int y) {
  const glm::vec3 dir = cameraRayDirection(camera, kWidth, kHeight, float(x), float(y));
  return pickVoxel(world, glm::vec3(camera.position), dir);
}

// A pixel of the 3D view right of the panel whose 7 x 7 neighbourhood picks one slot, so the
// click removes that slot whatever the rounding.
std::optional<glm::ivec2> solidPixel(const VoxelWorld& world, const Camera& camera) {
  for (int y = kHeight / 3; y < kHeight * 3 / 4; y += 8)
    for (int x = kWidth * 9 / 10; x > kWidth * 6 / 10; x -= 8) {
      const Pick centre = pickAt(world, camera, x, y);
      bool same = centre.hit;
      for (int dy = -3; dy <= 3 && same; ++dy)
        for (int dx = -3; dx <= 3 && same; ++dx) {
          const Pick p = pickAt(world, camera, x + dx, y + dy);
          same = p.hit && p.slot == centre.slot;
        }
      if (same) return glm::ivec2(x, y);
    }
  return std::nullopt;
}

// A pixel in the status bar's bottom padding, right of its text, with a block behind it.
std::optional<glm::ivec2> blockBehindStatusBar(const VoxelWorld& world, const Camera& camera) {
  for (int y = kHeight - 3; y > kHeight - 7; --y)
    for (int x = kWidth / 2; x < kWidth * 3 / 4; x += 4)
      if (pickAt(world, camera, x, y).hit) return glm::ivec2(x, y);
  return std::nullopt;
}

std::string slotText(const glm::ivec3& s) {
  return std::to_string(s.x) + "," + std::to_string(s.y) + "," + std::to_string(s.z);
}

TEST(ViewerInput, ShortClicksAndKeyTapsCountWhenFramesAreSlow) {
  RDM_TEST_REQUIRE(shell("command -v Xvfb") == 0, "Xvfb is not installed (package xvfb)");
  RDM_TEST_REQUIRE(shell("command -v xdotool") == 0,
                   "xdotool is not installed (scripts/install_deps.sh installs it)");
  const std::string dir = test::freshTestDir("viewer_input", "window");
  Scene scene = builtinScene("chess").value();
  scene.bake.spp = 1, scene.bake.max_hemisphere = 4;  // the in-process bake takes seconds
  scene.face_light_spp = 0;
  ASSERT_TRUE(writeFileAtomic(dir + "/chess.json", sceneToJson(scene)).ok());
  const VoxelWorld world = buildWorld(scene);
  CameraController controller;
  controller.reset(scene.cameras[0]);
  const Camera camera = controller.camera();
  const std::optional<glm::ivec2> target = solidPixel(world, camera);
  ASSERT_TRUE(target.has_value()) << "no block right of the panel in camera 0's view";
  const glm::ivec3 slot = pickAt(world, camera, target->x, target->y).slot;
  // The status bar (live_overlay.cpp, default ImGui style: 8 px padding, 19 px rows): its
  // first button, and a blank spot in its bottom padding with a block behind it, so a click
  // that ImGui takes and that also reached the world would remove that block.
  const glm::ivec2 button(30, kHeight - 37);
  const std::optional<glm::ivec2> blank = blockBehindStatusBar(world, camera);
  ASSERT_TRUE(blank.has_value()) << "no block behind the status bar's bottom edge";

  Xvfb xvfb;
  ASSERT_FALSE(xvfb.display().empty()) << "Xvfb did not start";
  const std::string out = dir + "/viewer.txt";
  Child viewer({RDM_VIEWER_BINARY, "--scene", dir + "/chess.json", "--width",
                std::to_string(kWidth), "--height", std::to_string(kHeight), "--tool", "remove",
                "--min-frame-ms", std::to_string(kMinFrameMs), "--frames", "100000"},
               xvfb.display(), out);
  const std::string xdo = "DISPLAY=" + xvfb.display() + " timeout 60 xdotool ";
  ASSERT_NE(waitForLine(out, "device:", viewer).find("device:"), std::string::npos)
      << fileText(out);
  ASSERT_EQ(shell(xdo + "search --sync --name '^rdm-viewer$'"), 0) << "no viewer window";
  std::this_thread::sleep_for(std::chrono::milliseconds(2 * kMinFrameMs));  // first frames
  auto move = [&](glm::ivec2 p) {
    return shell(xdo + "mousemove " + std::to_string(p.x) + " " + std::to_string(p.y));
  };
  // The window sits at the screen's origin: Xvfb runs no window manager.
  ASSERT_EQ(move(*target), 0);
  ASSERT_EQ(shell(xdo + "mousedown 1 sleep 0.1 mouseup 1"), 0);
  const std::string removed = "edit: remove block " + slotText(slot);
  std::string text = waitForLine(out, removed, viewer);
  ASSERT_NE(text.find(removed), std::string::npos) << "the 0.1 s click was lost:\n" << text;
  ASSERT_EQ(shell(xdo + "keydown ctrl+z sleep 0.1 keyup ctrl+z"), 0);
  text = waitForLine(out, "edit: undo", viewer);
  ASSERT_NE(text.find("edit: undo"), std::string::npos) << "the 0.1 s Ctrl+Z was lost:\n" << text;
  ASSERT_EQ(move(*blank), 0);
  ASSERT_EQ(shell(xdo + "mousedown 1 sleep 0.1 mouseup 1"), 0);
  ASSERT_EQ(move(button), 0);
  ASSERT_EQ(shell(xdo + "mousedown 1 sleep 0.1 mouseup 1"), 0);
  text = waitForLine(out, "live: job ", viewer);
  EXPECT_NE(text.find("live: job "), std::string::npos)
      << "ImGui did not get the click on \"bake in-process\":\n"
      << text;
  EXPECT_EQ(occurrences(text, "edit: "), 2u) << "one removal and one undo, nothing else:\n" << text;
}

}  // namespace
}  // namespace rdm::viewer
#endif  // RDM_VIEWER_BINARY
