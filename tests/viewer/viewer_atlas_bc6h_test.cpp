// rdm-viewer on a bc6h atlas (docs/bc6h.md, "The BC6H atlas"): the pages are decoded on the
// CPU into the RGBA16F texture, and the chess frame stays close to the float32 atlas's.
// Built with the viewer only.
#include <gtest/gtest.h>

#ifdef RDM_VIEWER_BINARY
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "rdm/image/exr_io.h"
#include "rdm/image/flip.h"
#include "rdm/image/tonemap.h"
#include "renderer.h"
#include "test_requirements.h"

namespace rdm::viewer {
namespace {

namespace fs = std::filesystem;

int runShell(const std::string& cmd, const std::string& log) {
  const int status = std::system((cmd + " > " + log + " 2>&1").c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string logText(const std::string& path) {
  std::ifstream in(path);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// Bakes chess in `radiance` into dir/atlas and renders camera 0 offscreen; the HDR frame.
Expected<Image> bakeAndRender(const std::string& dir, const std::string& radiance) {
  const std::string bake = std::string(RDM_BINARY) +
                           " bake --scene chess --spp 4 --max-hemisphere 16 --max-bounces 2 "
                           "--seed 3 --quiet --radiance " +
                           radiance + " -o " + dir + "/atlas";
  if (runShell(bake, dir + "/bake.log") != 0) return Status::error(logText(dir + "/bake.log"));
  const std::string view = std::string(RDM_VIEWER_BINARY) + " --scene chess --atlas " + dir +
                           "/atlas --width 320 --height 180 --offscreen " + dir +
                           "/out.png --exr " + dir + "/out.exr";
  if (runShell(view, dir + "/view.log") != 0) return Status::error(logText(dir + "/view.log"));
  return readFiniteExr(dir + "/out.exr", kRgbChannels);
}

std::string freshDir(const std::string& name) {
  const std::string dir =
      testing::TempDir() + "/viewer_bc6h_" + std::to_string(getpid()) + "_" + name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// The chess frame from the bc6h atlas against the float32 atlas's: LDR-FLIP (Reinhard + sRGB,
// as rdm flip) at most 0.003, issue 43's bound for what BC6H may add.
TEST(ViewerAtlasBc6h, ChessFrameIsCloseToTheFloatAtlas) {
  auto context = VulkanContext::create({});
  RDM_TEST_REQUIRE(context.ok(), "no Vulkan device: " << (context.ok() ? "" : context.error()));
  const std::string f32_dir = freshDir("f32"), bc6h_dir = freshDir("bc6h");
  auto reference = bakeAndRender(f32_dir, "float32");
  ASSERT_TRUE(reference.ok()) << reference.error();
  auto test = bakeAndRender(bc6h_dir, "bc6h");
  ASSERT_TRUE(test.ok()) << test.error();
  EXPECT_TRUE(fs::exists(bc6h_dir + "/atlas/atlas.ktx2"));
  const double ldr =
      computeLdrFlip(tonemapReinhardSrgb(*reference), tonemapReinhardSrgb(*test)).mean;
  const double hdr = computeHdrFlip(*reference, *test).mean;
  std::printf("[ viewer ] bc6h vs float32 atlas, chess 320x180: LDR-FLIP %.5f, HDR-FLIP %.5f\n",
              ldr, hdr);
  EXPECT_LE(ldr, 0.003);
  fs::remove_all(f32_dir);
  fs::remove_all(bc6h_dir);
}

}  // namespace
}  // namespace rdm::viewer
#endif  // RDM_VIEWER_BINARY
