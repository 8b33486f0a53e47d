// `rdm render --camera INDEX|NAME`: a named camera renders the bytes its index renders, and a
// camera the scene lacks fails naming the scene's cameras.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "cli_run.h"
#include "rdm/base/file_util.h"
#include "rdm/scene/scene.h"

namespace rdm {
namespace {

constexpr const char* kTinyRender = " --spp 1 --width 16 --height 9 -q -o ";

// Chess as a file whose camera 1 is named "side".
std::string namedCameraScene(const std::string& dir) {
  std::filesystem::create_directories(dir);
  Scene scene = builtinScene("chess").value();
  EXPECT_GE(scene.cameras.size(), 2u);
  scene.cameras[1].name = "side";
  const std::string path = dir + "/chess.json";
  EXPECT_TRUE(saveSceneFile(path, scene).ok());
  return path;
}

TEST(CliCamera, RenderByNameMatchesRenderByIndex) {
  const std::string dir = tempDir("camera_name");
  const std::string scene = namedCameraScene(dir);
  const std::string render = "render --scene " + scene + kTinyRender;
  ASSERT_EQ(runRdm(render + dir + "/by_index.exr --camera 1").code, 0);
  const CliResult by_name = runRdm(render + dir + "/by_name.exr --camera side");
  ASSERT_EQ(by_name.code, 0) << by_name.err;
  auto a = readFileToString(dir + "/by_index.exr"), b = readFileToString(dir + "/by_name.exr");
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(*a, *b);
  ASSERT_EQ(runRdm(render + dir + "/first.exr --camera 0").code, 0);
  auto first = readFileToString(dir + "/first.exr");
  ASSERT_TRUE(first.ok());
  EXPECT_NE(*first, *a) << "cameras 0 and 1 should see different images";
}

TEST(CliCamera, UnknownCameraFailsNamingTheCameras) {
  const std::string dir = tempDir("camera_unknown");
  const std::string scene = namedCameraScene(dir);
  const std::string render = "render --scene " + scene + kTinyRender;
  for (const std::string camera : {"nope", "9"}) {
    SCOPED_TRACE(camera);
    const CliResult r = runRdm(render + dir + "/bad.exr --camera " + camera);
    EXPECT_EQ(r.code, 1);
    EXPECT_TRUE(contains(r.err, "no camera '" + camera + "'")) << r.err;
    EXPECT_TRUE(contains(r.err, "0, 1 (side)")) << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir + "/bad.exr"));
  }
  EXPECT_TRUE(contains(runRdm("render --help").out, "scene camera: index or name"));
}

}  // namespace
}  // namespace rdm
