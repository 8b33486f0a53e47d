// The viewer's face light (viewer/shaders/face_light.glsl, docs/spec.md section 6) on
// lavapipe: it replaces the RDM diffuse where it is baked, a baked furnace stays uniform, and
// an edited slot falls back to the RDMs. Built with the viewer only.
#include <gtest/gtest.h>

#ifdef RDM_VIEWER_BINARY
#include <cmath>

#include "rdm/bake/face_light.h"
#include "rdm/scene/scene.h"
#include "rdm/scene/world.h"
#include "renderer.h"
#include "test_requirements.h"

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

}  // namespace
}  // namespace rdm::viewer
#endif  // RDM_VIEWER_BINARY
