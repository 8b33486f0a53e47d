// rdm-viewer's scene cameras by name: offscreen `--camera NAME` shows the image of that
// camera's index, an unknown camera fails naming the scene's cameras, and in a window under
// its own Xvfb the F5 key (sent by xdotool) appends the current view to the scene file as
// camera "view_<n>", announced on stdout as "camera: saved view_<n> to FILE"; on a built-in
// scene it saves nothing and says how to export the scene.
#include <gtest/gtest.h>

#ifdef RDM_VIEWER_BINARY
#include <glm/glm.hpp>
#include <string>

#include "camera_controller.h"
#include "fresh_dir.h"
#include "rdm/base/file_util.h"
#include "rdm/scene/scene.h"
#include "test_requirements.h"
#include "vk_context.h"
#include "window_process.h"

namespace rdm::viewer {
namespace {

using window_test::Child;
using window_test::fileText;
using window_test::shell;

constexpr double kWaitSeconds = 60.0;  // per step; a passing run takes a few frames

// Chess as a file in `dir` whose camera 1 is named "side".
std::string namedCameraScene(const std::string& dir) {
  Scene scene = builtinScene("chess").value();
  scene.cameras[1].name = "side";
  scene.bake.spp = 1, scene.bake.max_hemisphere = 4;
  scene.face_light_spp = 0;
  const std::string path = dir + "/chess.json";
  EXPECT_TRUE(saveSceneFile(path, scene).ok());
  return path;
}

bool vulkanAvailable(std::string* why) {
  auto context = VulkanContext::create({});
  if (!context && why) *why = context.error();
  return context.ok();
}

TEST(ViewerCamera, OffscreenCameraByNameMatchesIndexAndUnknownFails) {
  std::string why;
  RDM_TEST_REQUIRE(vulkanAvailable(&why), "no Vulkan device: " << why);
  const std::string dir = test::freshTestDir("viewer_camera", "offscreen");
  const std::string base = std::string(RDM_VIEWER_BINARY) + " --scene " + namedCameraScene(dir) +
                           " --width 64 --height 36 --no-rdm ";
  auto run = [&](const std::string& camera, const std::string& png) {
    const std::string cmd = base + "--camera " + camera + " --offscreen " + dir + "/" + png +
                            " > " + dir + "/out.txt 2>&1";
    const int status = std::system(cmd.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  };
  ASSERT_EQ(run("1", "by_index.png"), 0) << fileText(dir + "/out.txt");
  ASSERT_EQ(run("side", "by_name.png"), 0) << fileText(dir + "/out.txt");
  const std::string by_index = fileText(dir + "/by_index.png");
  EXPECT_FALSE(by_index.empty());
  EXPECT_EQ(by_index, fileText(dir + "/by_name.png"));
  EXPECT_EQ(run("nope", "bad.png"), 1);
  const std::string err = fileText(dir + "/out.txt");
  EXPECT_NE(err.find("no camera 'nope'; the scene has 0, 1 (side)"), std::string::npos) << err;
}

// Starts the window on `scene` (camera `camera`) under its own Xvfb, taps F5 and returns the
// viewer's output once it holds `expected` (or after kWaitSeconds, or once the viewer ended).
std::string pressF5(const std::string& dir, const std::string& scene, const std::string& camera,
                    const std::string& expected) {
  window_test::Xvfb xvfb;
  EXPECT_FALSE(xvfb.display().empty()) << "Xvfb did not start";
  if (xvfb.display().empty()) return "";
  const std::string out = dir + "/viewer.txt";
  Child viewer({RDM_VIEWER_BINARY, "--scene", scene, "--camera", camera, "--width", "480",
                "--height", "270", "--frames", "100000"},
               xvfb.display(), out);
  const std::string xdo = "DISPLAY=" + xvfb.display() + " timeout 60 xdotool ";
  const std::string started = window_test::waitForLine(out, "device:", viewer, kWaitSeconds);
  EXPECT_NE(started.find("device:"), std::string::npos) << started;
  EXPECT_EQ(shell(xdo + "search --sync --name '^rdm-viewer$'"), 0) << "no viewer window";
  // Key events go to the window under the pointer: Xvfb runs no window manager.
  EXPECT_EQ(shell(xdo + "mousemove 450 50"), 0);
  EXPECT_EQ(shell(xdo + "keydown F5 sleep 0.1 keyup F5"), 0);
  return window_test::waitForLine(out, expected, viewer, kWaitSeconds);
}

TEST(ViewerCamera, F5SavesTheViewAsSceneCamera) {
  RDM_TEST_REQUIRE(shell("command -v Xvfb") == 0, "Xvfb is not installed (package xvfb)");
  RDM_TEST_REQUIRE(shell("command -v xdotool") == 0,
                   "xdotool is not installed (scripts/install_deps.sh installs it)");
  const std::string dir = test::freshTestDir("viewer_camera", "window");
  const std::string scene_path = namedCameraScene(dir);
  const std::string saved = "camera: saved view_0 to " + scene_path;
  const std::string text = pressF5(dir, scene_path, "side", saved);
  ASSERT_NE(text.find(saved), std::string::npos) << "F5 saved no view:\n" << text;

  auto scene = loadSceneFile(scene_path);
  ASSERT_TRUE(scene.ok()) << scene.error();
  ASSERT_EQ(scene->cameras.size(), 3u);
  const Camera& view = scene->cameras[2];
  EXPECT_EQ(view.name, "view_0");
  EXPECT_TRUE(cameraUsable(view));
  CameraController controller;  // the window's view as it starts, on camera "side"
  controller.reset(scene->cameras[1]);
  const Camera expected = controller.camera();
  EXPECT_LT(glm::distance(view.position, expected.position), 1e-3);
  EXPECT_LT(glm::distance(view.target, expected.target), 1e-3);
  EXPECT_NEAR(view.fov_deg, expected.fov_deg, 1e-3);
  auto found = findCamera(*scene, "view_0");
  ASSERT_TRUE(found.ok()) << found.error();
  EXPECT_EQ(*found, 2u);
}

TEST(ViewerCamera, F5OnBuiltInSceneSavesNothing) {
  RDM_TEST_REQUIRE(shell("command -v Xvfb") == 0, "Xvfb is not installed (package xvfb)");
  RDM_TEST_REQUIRE(shell("command -v xdotool") == 0,
                   "xdotool is not installed (scripts/install_deps.sh installs it)");
  const std::string dir = test::freshTestDir("viewer_camera", "builtin");
  const std::string refused = "camera: not saved: scene 'chess' is built in";
  const std::string text = pressF5(dir, "chess", "0", refused);
  EXPECT_NE(text.find(refused), std::string::npos) << text;
  EXPECT_NE(text.find("rdm scene --scene chess -o chess.json"), std::string::npos) << text;
  EXPECT_EQ(text.find("camera: saved"), std::string::npos) << text;
}

}  // namespace
}  // namespace rdm::viewer
#endif  // RDM_VIEWER_BINARY
