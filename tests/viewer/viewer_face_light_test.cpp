// The viewer's face light (viewer/shaders/face_light.glsl, docs/spec.md section 6) on
// lavapipe: it replaces the RDM diffuse where it is baked, a baked furnace stays uniform, and
// an edited slot falls back to the RDMs. Built with the viewer only.
#include <gtest/gtest.h>

#ifdef RDM_VIEWER_BINARY
#include <cmath>
#include <cstdlib>
#include <string>

#include "cli_run.h"
#include "rdm/bake/face_light.h"
#include "rdm/image/exr_io.h"
#include "rdm/scene/lights.h"
#include "rdm/scene/scene.h"
#include "rdm/scene/world.h"
#include "renderer.h"
#include "test_requirements.h"
#include "test_scenes.h"
#include "viewer_flip.h"

namespace rdm::viewer {
namespace {

// The furnace's exposed faces, every one holding `value`.
FaceLight uniformFaceLight(const Scene& scene, float value) {
  const VoxelWorld world = buildWorld(scene);
  FaceLight light;
  FaceLightSlot slot;
  slot.slot = {1, 1, 1};
  slot.faces = exposedFaces(world, slot.slot);
  slot.light.assign(slot.faces.size(), glm::vec3(value));
  light.slots.push_back(slot);
  light.spp = 4;
  return light;
}

struct Coverage {
  int dark = 0, pixels = 0;  // pixels below 0.5 (green), of all
};
Coverage darkPixels(const Image& hdr) {
  Coverage c;
  for (size_t i = 1; i < hdr.pixels.size(); i += 3, ++c.pixels) c.dark += hdr.pixels[i] < 0.5f;
  return c;
}

TEST(ViewerFaceLight, ReplacesTheDiffuseWhereBakedAndEditedSlotsFallBack) {
  auto context = VulkanContext::create({});
  RDM_TEST_REQUIRE(context.ok(),
                   "no Vulkan device: " << (context ? std::string() : context.error()));
  auto renderer = Renderer::create(**context, {64, 36, 256});
  ASSERT_TRUE(renderer.ok()) << renderer.error();
  Renderer& r = **renderer;
  Scene scene = builtinScene("furnace").value();
  const Camera camera = scene.cameras[0];
  ASSERT_TRUE(r.setScene(scene).ok());
  // Dark face light (0.1): the block's diffuse drops from ~1 to ~0.1 (plus ~0.04 specular
  // from the ambient), the sky stays 1.
  ASSERT_TRUE(r.setFaceLight(uniformFaceLight(scene, 0.1f)).ok());
  ASSERT_TRUE(r.renderFrame(camera, kTermDefault).ok());
  const Coverage with = darkPixels(r.readHdr().value());
  EXPECT_GT(with.dark, with.pixels / 50);              // the block covers 3.6 % of the view
  ASSERT_TRUE(r.renderFrame(camera, kTermBase).ok());  // the term off: ambient as before
  EXPECT_EQ(darkPixels(r.readHdr().value()).dark, 0);
  // One voxel removed: setScene re-bakes the slot (the light's spp, 4), whose faces all see
  // the unit sky again.
  scene.blocks["white"].voxels[0] = 0;
  ASSERT_TRUE(r.setScene(scene).ok());
  ASSERT_TRUE(r.renderFrame(camera, kTermDefault).ok());
  EXPECT_EQ(darkPixels(r.readHdr().value()).dark, 0);
}

TEST(ViewerFaceLight, BakedFurnaceRendersUniform) {
  auto context = VulkanContext::create({});
  RDM_TEST_REQUIRE(context.ok(),
                   "no Vulkan device: " << (context ? std::string() : context.error()));
  auto renderer = Renderer::create(**context, {64, 36, 256});
  ASSERT_TRUE(renderer.ok()) << renderer.error();
  const Scene scene = builtinScene("furnace").value();
  ASSERT_TRUE((*renderer)->setScene(scene).ok());
  FaceLight light = bakeFaceLight(buildWorld(scene), scene, {2, 4});
  ASSERT_EQ(light.faceCount(), 6u * 256u);
  ASSERT_TRUE((*renderer)->setFaceLight(std::move(light)).ok());
  ASSERT_TRUE((*renderer)->renderFrame(scene.cameras[0], kTermDefault).ok());
  // Every face sees only the unit sky: light 1, so every pixel is within the furnace
  // tolerance of ViewerRenderer.FurnaceWithoutRdmsIsUniform ((1-F0) C + F0 A + B ~ 0.97-1.02).
  const Image hdr = (*renderer)->readHdr().value();  // a copy: the Expected is a temporary
  for (float v : hdr.pixels) EXPECT_NEAR(v, 1.0f, 0.05f);
}

// Issue 39: enabling the face light at a scene's default spp never raises FLIP. island (four
// lamps and the sun), island at night (lamps, a dim sky, no sun: where a face light that found
// emitters only by chance was blotchy) and chess (sun and sky), each against a path-traced
// reference (128 spp). Measured 2026-12-07 on lavapipe, without -> with -> with the face light
// filter: island 0.01747 -> 0.01036 -> 0.01029, at night 0.01744 -> 0.00914 -> 0.00903, chess
// 0.01546 -> 0.01151 -> 0.01139 (docs/results.md sections 1f and 1h).
TEST(ViewerFaceLight, TheFaceLightAtItsDefaultSppNeverRaisesFlip) {
  Scene night = builtinScene("island").value();
  night.sky = Sky{{0.004, 0.006, 0.012}, {0.01, 0.012, 0.016}, {0.003, 0.003, 0.003}};
  night.sun.reset();
  night.ambient = {0.01, 0.01, 0.012};
  const std::string base = tempDir("viewer_face_light_flip");
  std::filesystem::create_directories(base);
  ASSERT_TRUE(saveSceneFile(base + "/island_night.json", night).ok());
  const std::string without = "rdm,diffuse,specular,sun,shadows,emission,background,in-block";
  for (const std::string& scene :
       std::vector<std::string>{"island", base + "/island_night.json", "chess"}) {
    const std::string dir = base + "/" + std::to_string(std::hash<std::string>()(scene));
    std::filesystem::create_directories(dir);
    ASSERT_EQ(runRdm("bake --scene " + scene + " -q -o " + dir + "/atlas").code, 0) << scene;
    ASSERT_EQ(runRdm("render --scene " + scene + " --camera 0 --spp 128 --width 320 " +
                     "--height 180 -q -o " + dir + "/ref.exr")
                  .code,
              0)
        << scene;
    const double with_light = viewerFlip(dir, scene, without + ",face-light", "with");
    const double without_light = viewerFlip(dir, scene, without, "without");
    const double filtered =
        viewerFlip(dir, scene, without + ",face-light,face-light-filter", "filtered");
    std::printf("[ viewer ] %s: LDR-FLIP %.5f without the face light, %.5f with, %.5f filtered\n",
                scene.c_str(), without_light, with_light, filtered);
    ASSERT_GT(with_light, 0.0) << scene;
    ASSERT_GT(without_light, 0.0) << scene;
    ASSERT_GT(filtered, 0.0) << scene;
    EXPECT_LT(with_light, without_light) << scene;
    EXPECT_LT(filtered, with_light) << scene;
  }
}

// Mean luminance of the pixels [x0, x1) x [y0, y1) of an RGB EXR; -1 when it cannot be read.
double patchLuminance(const std::string& path, int x0, int x1, int y0, int y1) {
  const Expected<Image> image = readExr(path, kRgbChannels);
  if (!image.ok()) return -1.0;
  double sum = 0.0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      const float* p = &image->pixels[3 * (size_t(y) * image->width + x)];
      sum += luminance(glm::vec3(p[0], p[1], p[2]));
    }
  return sum / double((x1 - x0) * (y1 - y0));
}

// Issue 40 item 5: an emitter lights the surfaces of its own block in the viewer. A pink
// emissive rod on a grey floor in the middle block of 3 x 3, a dim sky: the floor in front of
// the rod's foot is pink in the reference. The level-7 RDM sees the block from its boundary
// and cannot carry it; the face light (the default) does. Measured 2026-12-07 at 320 x 180:
// the patch's luminance 0.0457 in the reference (128 spp), 0.0467 with the face light, 0.0192
// without it; LDR-FLIP 0.0133 and 0.0558. Bounds: within 15 % with it (the reference's noise
// over the patch is under 3 %), under half without.
TEST(ViewerFaceLight, AnEmitterLightsTheFloorOfItsOwnBlock) {
  Scene s;
  s.size = {3, 1, 3};
  s.palette = {{{150, 150, 150}, 7, 0, 0}, {{255, 80, 160}, 7, 0, 3}};
  s.blocks["floor"] = test::blockFrom([](int, int y, int) { return y == 0 ? 1 : 0; });
  s.blocks["rod"] = test::blockFrom(
      [](int x, int y, int z) { return y == 0 ? 1 : (x == 8 && z == 8 && y <= 5 ? 2 : 0); });
  for (int k = 0; k < 3; ++k)
    for (int i = 0; i < 3; ++i)
      s.placements.push_back({{i, 0, k}, i == 1 && k == 1 ? "rod" : "floor", 0});
  s.sky = Sky{{0.05, 0.06, 0.08}, {0.06, 0.07, 0.08}, {0.02, 0.02, 0.02}};
  s.ambient = {0.05, 0.06, 0.08};
  s.emission_scale = 4.0;
  s.face_light_spp = 64;
  s.cameras = {{{1.5, 1.2, 0.3}, {1.5, 0.0, 1.5}, 50.0}};
  const std::string dir = tempDir("viewer_face_light_rod");
  std::filesystem::create_directories(dir);
  ASSERT_TRUE(saveSceneFile(dir + "/rod.json", s).ok());
  const std::string scene = dir + "/rod.json";
  ASSERT_EQ(runRdm("bake --scene " + scene + " -q -o " + dir + "/atlas").code, 0);
  ASSERT_EQ(runRdm("render --scene " + scene + " --spp 128 --width 320 --height 180 -q -o " + dir +
                   "/ref.exr")
                .code,
            0);
  const std::string without = "rdm,diffuse,specular,sun,shadows,emission,background,in-block";
  const double flip_with = viewerFlip(dir, scene, without + ",face-light", "with");
  const double flip_without = viewerFlip(dir, scene, without, "without");
  ASSERT_GT(flip_with, 0.0);
  ASSERT_GT(flip_without, 0.0);
  // The floor just in front of the rod's foot (the rod covers x 151-160, y 48-85).
  auto floor = [&](const std::string& name) {
    return patchLuminance(dir + "/" + name + ".exr", 140, 172, 88, 100);
  };
  const double ref = floor("ref"), with_light = floor("with"), without_light = floor("without");
  std::printf(
      "[ viewer ] floor by the rod: reference %.4f, with the face light %.4f, without "
      "%.4f; LDR-FLIP %.4f with, %.4f without\n",
      ref, with_light, without_light, flip_with, flip_without);
  ASSERT_GT(ref, 0.0);
  EXPECT_LT(without_light, 0.5 * ref);
  EXPECT_NEAR(with_light, ref, 0.15 * ref);
}

}  // namespace
}  // namespace rdm::viewer
#endif  // RDM_VIEWER_BINARY
