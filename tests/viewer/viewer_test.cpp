// The viewer: CPU pieces in process (mesher, DFG tables, camera), the
// Vulkan renderer in process (atlas deltas), and rdm-viewer as a user runs it: offscreen
// renders of chess and island compared with golden images, RDM on/off, a window under Xvfb.
// Without a Vulkan device or xvfb-run the tests fail, or skip with RDM_TEST_ALLOW_SKIP=1.
#include <gtest/gtest.h>
#include <unistd.h>

// RDM_VIEWER_BINARY and the renderer's include paths come from viewer/CMakeLists.txt; with
// RDM_BUILD_VIEWER=OFF this file only reports the viewer as not built.
#ifndef RDM_VIEWER_BINARY
TEST(Viewer, NotBuilt) {
  GTEST_SKIP() << "configured with RDM_BUILD_VIEWER=OFF";
}
#else
#include <stb_image.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

#include "atlas_texture.h"
#include "camera.h"
#include "mesher.h"
#include "rdm/bake/render.h"
#include "rdm/image/exr_io.h"
#include "rdm/image/png_io.h"
#include "renderer.h"
#include "shading_tables.h"
#include "test_requirements.h"

namespace rdm::viewer {
namespace {

namespace fs = std::filesystem;

// ---- helpers -------------------------------------------------------------------------

// Runs `cmd` with stdout to `out` and stderr to `err` (default: both discarded).
int runCommand(const std::string& cmd, const std::string& out = "/dev/null",
               const std::string& err = "/dev/null") {
  const int status = std::system((cmd + " > " + out + " 2> " + err).c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string fileText(const std::string& path) {
  std::ifstream in(path);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

std::string testDir(const std::string& name) {
  // Per process: ctest runs tests in parallel processes that must not share directories.
  const std::string dir = testing::TempDir() + "/viewer_" + std::to_string(getpid()) + "_" + name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// An 8-bit RGB or RGBA PNG, decoded by stb_image.
bool readPng(const std::string& path, Image8& out) {
  int channels = 0;
  uint8_t* pixels = stbi_load(path.c_str(), &out.width, &out.height, &channels, 0);
  if (!pixels) return false;
  out.channels = channels;
  out.pixels.assign(pixels, pixels + size_t(out.width) * out.height * channels);
  stbi_image_free(pixels);
  return channels == 3 || channels == 4;
}

struct ImageDiff {
  double mean_abs = 0.0;   // mean |a - b| over all channels, in 1/255 units
  double frac_over = 0.0;  // fraction of pixels with some channel differing by > threshold
};

ImageDiff diffImages(const Image8& a, const Image8& b, int threshold, int x0 = 0, int y0 = 0,
                     int x1 = -1, int y1 = -1) {
  ImageDiff d;
  if (x1 < 0) x1 = a.width;
  if (y1 < 0) y1 = a.height;
  size_t count = 0, over = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      int worst = 0;
      for (int c = 0; c < 3; ++c) {
        const int v = std::abs(int(a.pixels[(size_t(y) * a.width + x) * a.channels + c]) -
                               int(b.pixels[(size_t(y) * b.width + x) * b.channels + c]));
        d.mean_abs += v, worst = std::max(worst, v);
      }
      over += worst > threshold ? 1 : 0, ++count;
    }
  d.mean_abs /= double(count * 3);
  d.frac_over = double(over) / double(count);
  return d;
}

bool vulkanAvailable(std::string* why) {
  auto context = VulkanContext::create({});
  if (!context && why) *why = context.error();
  return context.ok();
}

#define REQUIRE_VULKAN()                                        \
  do {                                                          \
    std::string why_;                                           \
    const bool available_ = vulkanAvailable(&why_);             \
    RDM_TEST_REQUIRE(available_, "no Vulkan device: " << why_); \
  } while (0)

// Atlases baked once per process at tiny settings, and the offscreen renders.
constexpr int kWidth = 320, kHeight = 180;
const char* kBakeSettings = " --spp 4 --max-hemisphere 16 --max-bounces 2 --quiet";

const std::string& bakedAtlas(const std::string& scene) {
  static std::map<std::string, std::string> dirs;
  if (!dirs.count(scene)) {
    const std::string dir = testDir("atlas_" + scene);
    const int rc = runCommand(std::string(RDM_BINARY) + " bake --scene " + scene + kBakeSettings +
                              " -o " + dir);
    dirs[scene] = rc == 0 ? dir : "";
  }
  return dirs[scene];
}

// Runs rdm-viewer offscreen; returns the PNG (and reads the EXR into `hdr` when given).
// Failures are reported with the command's stderr.
bool renderOffscreen(const std::string& scene, const std::string& extra, Image8& ldr,
                     Image* hdr = nullptr) {
  const std::string atlas = bakedAtlas(scene);
  if (atlas.empty()) return ADD_FAILURE() << "rdm bake failed for " << scene, false;
  const std::string dir =
      testDir("render_" + scene + std::to_string(std::hash<std::string>()(extra) % 100000));
  const std::string cmd = std::string(RDM_VIEWER_BINARY) + " --scene " + scene + " --atlas " +
                          atlas + " --width " + std::to_string(kWidth) + " --height " +
                          std::to_string(kHeight) + " --offscreen " + dir + "/out.png --exr " +
                          dir + "/out.exr " + extra;
  if (const int rc = runCommand(cmd, dir + "/stdout.txt", dir + "/stderr.txt"); rc != 0) {
    return ADD_FAILURE() << cmd << "\nexit " << rc << ": " << fileText(dir + "/stderr.txt"), false;
  }
  if (!readPng(dir + "/out.png", ldr))
    return ADD_FAILURE() << "unreadable " << dir << "/out.png", false;
  if (hdr) {
    auto image = readExr(dir + "/out.exr", kRgbChannels);
    if (!image) return false;
    *hdr = std::move(*image);
  }
  return true;
}

// ---- CPU pieces ----------------------------------------------------------------------

int exposedFaces(const std::array<uint8_t, 4096>& v) {
  auto solid = [&](int x, int y, int z) {
    return x >= 0 && y >= 0 && z >= 0 && x < 16 && y < 16 && z < 16 && v[x + 16 * y + 256 * z] != 0;
  };
  int n = 0;
  for (int z = 0; z < 16; ++z)
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x) {
        if (!solid(x, y, z)) continue;
        n += !solid(x + 1, y, z) + !solid(x - 1, y, z) + !solid(x, y + 1, z) + !solid(x, y - 1, z) +
             !solid(x, y, z + 1) + !solid(x, y, z - 1);
      }
  return n;
}

TEST(ViewerMesher, FullBlockIsSixQuadsAndSphereAreaMatchesExposedFaces) {
  std::array<uint8_t, 4096> full;
  full.fill(1);
  EXPECT_EQ(greedyMesh(full).quadCount(), 6);
  std::array<uint8_t, 4096> sphere{};
  for (int z = 0; z < 16; ++z)
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x) {
        const double dx = x + 0.5 - 8, dy = y + 0.5 - 8, dz = z + 0.5 - 8;
        sphere[x + 16 * y + 256 * z] = dx * dx + dy * dy + dz * dz <= 6.5 * 6.5 ? 2 : 0;
      }
  const BlockMesh mesh = greedyMesh(sphere);
  int area = 0;
  for (int q = 0; q < mesh.quadCount(); ++q) {
    glm::ivec3 lo(99), hi(-1);
    for (int k = 0; k < 4; ++k)
      for (int a = 0; a < 3; ++a) {
        lo[a] = std::min(lo[a], vertexCoord(mesh.vertices[4 * q + k], a));
        hi[a] = std::max(hi[a], vertexCoord(mesh.vertices[4 * q + k], a));
      }
    const glm::ivec3 e = hi - lo;
    area += std::max(e.x, 1) * std::max(e.y, 1) * std::max(e.z, 1);
  }
  EXPECT_EQ(area, exposedFaces(sphere));
  EXPECT_LT(mesh.quadCount(), exposedFaces(sphere) / 2);  // merging happened
}

// The in-block walk skips empty 4^3 bricks by the masks that follow the voxel words: for each
// block, bit (x >> 2) | (y >> 2) << 2 | (z >> 2) << 4 is set exactly when that brick holds a
// solid voxel.
TEST(ViewerSceneData, BrickMasksFollowTheVoxelWords) {
  const Scene scene = builtinScene("mirror_floor").value();
  const VoxelWorld world = buildWorld(scene);
  const SceneGpuData data = buildSceneGpuData(scene, world);
  const size_t blocks = world.blocks.size();
  ASSERT_EQ(data.voxels.size(), blocks * 4098);
  int empty_bricks = 0;
  for (size_t b = 0; b < blocks; ++b) {
    const uint64_t mask = uint64_t(data.voxels[blocks * 4096 + 2 * b]) |
                          uint64_t(data.voxels[blocks * 4096 + 2 * b + 1]) << 32;
    for (int brick = 0; brick < 64; ++brick) {
      bool solid = false;
      for (int v = 0; v < 64; ++v) {
        const int x = (brick & 3) * 4 + (v & 3), y = (brick >> 2 & 3) * 4 + (v >> 2 & 3),
                  z = (brick >> 4) * 4 + (v >> 4);
        solid = solid || (data.voxels[b * 4096 + x + 16 * y + 256 * z] >> 24) != 0;
      }
      EXPECT_EQ(bool(mask >> brick & 1), solid) << "block " << b << " brick " << brick;
      empty_bricks += !solid;
    }
  }
  EXPECT_GT(empty_bricks, 0);  // the floor's block has air above the floor
}

TEST(ViewerTables, WhiteDielectricAlbedoMatchesSpecSection5) {
  // docs/spec.md section 5: white dielectric at r = 7 has directional albedo 0.972 at normal view,
  // 0.984 at cos 0.2: (1 - F0) C(mu) + F0 A + B with F0 = 0.04.
  for (auto [mu, expected] : {std::pair{1.0f, 0.972f}, {0.2f, 0.984f}}) {
    const glm::vec2 ab = integrateDfg(1.0f, mu, 16384);
    const float c = integrateDiffuseAlbedo(mu, 16384);
    EXPECT_NEAR(0.96f * c + 0.04f * ab.x + ab.y, expected, 0.004f) << "mu " << mu;
  }
  const glm::vec2 mirror = integrateDfg(0.0f, 0.5f, 1);  // delta lobe: A + B = 1
  EXPECT_FLOAT_EQ(mirror.x + mirror.y, 1.0f);
  const ShadingTables tables = computeShadingTables(256);
  EXPECT_EQ(tables.dfg.size(), size_t(kDfgRows * kDfgColumns));
}

TEST(ViewerCamera, RasterPixelCentresSeeSpecCameraRays) {
  const Camera camera{{-2.0, 5.0, -2.0}, {4.0, 1.0, 4.0}, 50.0};
  const CameraBasis basis = cameraBasis(camera).value();
  const int w = 320, h = 180;
  const glm::mat4 vp = viewProjection(basis, float(w) / float(h));
  for (auto [x, y] : {std::pair{0, 0}, {319, 179}, {160, 90}, {17, 150}}) {
    const glm::vec3 d = cameraRayDirection(camera, w, h, x + 0.5f, y + 0.5f);
    const glm::vec4 clip = vp * glm::vec4(glm::vec3(camera.position) + 7.0f * d, 1.0f);
    const float px = (clip.x / clip.w * 0.5f + 0.5f) * w, py = (clip.y / clip.w * 0.5f + 0.5f) * h;
    EXPECT_NEAR(px, x + 0.5f, 1e-3f);
    EXPECT_NEAR(py, y + 0.5f, 1e-3f);
    EXPECT_GT(clip.z / clip.w, 0.0f);
    EXPECT_LT(clip.z / clip.w, 1.0f);
  }
  EXPECT_FALSE(cameraBasis(Camera{{0, 0, 0}, {0, 3, 0}, 50}).ok());
}

// ---- Vulkan in process ---------------------------------------------------------------

// An incremental job's new RDMs grow a page; within the device image's headroom that costs
// no new image: the page keeps its texels, the grown rows are zero and rects land there.
TEST(ViewerAtlas, PagesGrowInPlaceWithinTheHeadroom) {
  REQUIRE_VULKAN();
  auto context = VulkanContext::create({});
  ASSERT_TRUE(context.ok()) << context.error();
  Image page(96, 72, 4);
  for (size_t i = 0; i < page.pixels.size(); ++i) page.pixels[i] = 1.0f + float(i % 97);
  auto atlas = AtlasTexture::create(**context, {page});
  ASSERT_TRUE(atlas.ok()) << atlas.error();
  EXPECT_GE((*atlas)->height(), 90);                // 72 and a quarter, rounded up to 64 rows: 128
  EXPECT_FALSE((*atlas)->growInPlace({{96, 64}}));  // shrinks
  EXPECT_FALSE((*atlas)->growInPlace({{96, 72}, {96, 72}}));  // a page more
  EXPECT_FALSE((*atlas)->growInPlace({{96, (*atlas)->height() + 1}}));
  ASSERT_TRUE((*atlas)->growInPlace({{96, 90}}));
  ASSERT_EQ((*atlas)->pageSizes()[0].height, 90);
  Image rect(4, 6, 4);
  std::fill(rect.pixels.begin(), rect.pixels.end(), -3.0f);
  ASSERT_TRUE((*atlas)->applyDelta({{0, 8, 80, rect}}).ok());  // in the grown rows
  auto back = (*atlas)->readLayer(0);
  ASSERT_TRUE(back.ok()) << back.error();
  for (int y = 0; y < 90; ++y)
    for (int x = 0; x < 96; ++x)
      for (int c = 0; c < 4; ++c) {
        const bool in_rect = x >= 8 && x < 12 && y >= 80 && y < 86;
        const float want = y < 72 ? page.at(x, y, c) : (in_rect ? -3.0f : 0.0f);
        ASSERT_EQ(back->at(x, y, c), want) << x << "," << y;  // integers: exact at half
        if (c == 3) {
          ASSERT_EQ((*atlas)->depthMask().any(0, x, y, 1, 1), want != 0.0f);
        }
      }
}

TEST(ViewerAtlas, DeltaUpdatesExactlyTheGivenRects) {
  REQUIRE_VULKAN();
  auto context = VulkanContext::create({});
  ASSERT_TRUE(context.ok()) << context.error();
  Image page(96, 72, 4);
  for (size_t i = 0; i < page.pixels.size(); ++i) page.pixels[i] = float(i % 9973) * 0.25f;
  auto atlas = AtlasTexture::create(**context, {page});
  ASSERT_TRUE(atlas.ok()) << atlas.error();
  std::vector<AtlasRectUpdate> updates = {{0, 8, 12, Image(4, 6, 4)},
                                          {0, 60, 30, Image(16, 24, 4)}};
  for (auto& u : updates) std::fill(u.texels.pixels.begin(), u.texels.pixels.end(), -7.5f);
  ASSERT_TRUE((*atlas)->applyDelta(updates).ok());
  auto back = (*atlas)->readLayer(0);
  ASSERT_TRUE(back.ok()) << back.error();
  int changed = 0;
  for (int y = 0; y < page.height; ++y)
    for (int x = 0; x < page.width; ++x) {
      bool inside = false;
      for (const auto& u : updates) {
        inside |= x >= u.x && x < u.x + u.texels.width && y >= u.y && y < u.y + u.texels.height;
      }
      for (int c = 0; c < 4; ++c) {  // the device holds half: page values rounded to it
        ASSERT_EQ(back->at(x, y, c), inside ? -7.5f : atlasFloat(atlasHalf(page.at(x, y, c))))
            << x << "," << y << "," << c;
      }
      // The depth mask (the slot table's only view of the texels) follows.
      ASSERT_EQ((*atlas)->depthMask().any(0, x, y, 1, 1), back->at(x, y, 3) != 0.0f);
      changed += inside;
    }
  EXPECT_EQ(changed, 4 * 6 + 16 * 24);
  EXPECT_FALSE((*atlas)->applyDelta({{0, 90, 70, Image(8, 8, 4)}}).ok());  // leaves the page
}

TEST(ViewerRenderer, FurnaceWithoutRdmsIsUniform) {
  REQUIRE_VULKAN();
  auto context = VulkanContext::create({});
  ASSERT_TRUE(context.ok());
  auto renderer = Renderer::create(**context, {64, 36, 256});
  ASSERT_TRUE(renderer.ok()) << renderer.error();
  Scene scene = builtinScene("furnace").value();
  ASSERT_TRUE((*renderer)->setScene(scene).ok());
  ASSERT_TRUE((*renderer)->renderFrame(scene.cameras[0], kTermBase).ok());
  auto hdr = (*renderer)->readHdr();
  ASSERT_TRUE(hdr.ok());
  // The furnace: white sky everywhere, white block lit by ambient 1 without RDMs: every
  // pixel's radiance is close to 1 (sky exactly 1; the block (1-F0) C + F0 A + B ~ 0.97-1.02).
  for (float v : hdr->pixels) EXPECT_NEAR(v, 1.0f, 0.05f);
}

// The interactive resolution: a frame at divisor 2 is the half-size frame, each pixel
// repeated 2 x 2 (same rasterisation and shading; exact on one device).
TEST(ViewerRenderer, ResolutionDivisorRepeatsTheHalfSizeFrame) {
  REQUIRE_VULKAN();
  auto context = VulkanContext::create({});
  ASSERT_TRUE(context.ok());
  Scene scene = builtinScene("chess").value();
  auto full = Renderer::create(**context, {128, 72, 256});
  auto half = Renderer::create(**context, {64, 36, 256});
  ASSERT_TRUE(full.ok() && half.ok());
  for (Renderer* r : {full->get(), half->get()}) ASSERT_TRUE(r->setScene(scene).ok());
  (*full)->setResolutionDivisor(2);
  ASSERT_TRUE((*full)->renderFrame(scene.cameras[0], kTermBase).ok());
  ASSERT_TRUE((*half)->renderFrame(scene.cameras[0], kTermBase).ok());
  auto big = (*full)->readLdr(), small = (*half)->readLdr();
  ASSERT_TRUE(big.ok() && small.ok());
  int varied = 0;
  for (int y = 0; y < 72; ++y)
    for (int x = 0; x < 128; ++x)
      for (int c = 0; c < 3; ++c) {
        const uint8_t want = small->pixels[(size_t(y / 2) * 64 + size_t(x / 2)) * 3 + size_t(c)];
        ASSERT_EQ(big->pixels[(size_t(y) * 128 + size_t(x)) * 3 + size_t(c)], want)
            << x << "," << y << "," << c;
        varied += want != small->pixels[size_t(c)];
      }
  EXPECT_GT(varied, 1000);           // not a blank image
  (*full)->setResolutionDivisor(1);  // and back: the full frame differs from the repeated one
  ASSERT_TRUE((*full)->renderFrame(scene.cameras[0], kTermBase).ok());
  auto again = (*full)->readLdr();
  ASSERT_TRUE(again.ok());
  EXPECT_NE(again->pixels, big->pixels);
}

// ---- rdm-viewer as a user runs it ----------------------------------------------------

// Golden comparison: mean |diff| <= 1.5 / 255 and at most 1% of pixels off by > 24 / 255
// (lavapipe is deterministic on one machine; the slack covers other LLVM vector widths).
void expectMatchesGolden(const std::string& name, const Image8& image) {
  const std::string path = std::string(RDM_TEST_DATA_DIR) + "/golden/" + name + ".png";
  // The render is kept beside the test's output, never over the golden: accepting a new
  // golden is a reviewed copy.
  const std::string rendered = testDir("golden_" + name) + "/" + name + ".png";
  ASSERT_TRUE(writePng(rendered, image.width, image.height, image.channels, image.pixels).ok());
  const std::string accept = "to accept this render: cp " + rendered + " " + path;
  Image8 golden;
  ASSERT_TRUE(readPng(path, golden)) << "missing golden " << path << "; " << accept;
  ASSERT_EQ(golden.width, image.width) << accept;
  ASSERT_EQ(golden.height, image.height) << accept;
  const ImageDiff d = diffImages(golden, image, 24);
  EXPECT_LE(d.mean_abs, 1.5) << name << "; " << accept;
  EXPECT_LE(d.frac_over, 0.01) << name << "; " << accept;
}

class ViewerOffscreen : public testing::TestWithParam<std::string> {};

TEST_P(ViewerOffscreen, RendersNotBlankMatchesGoldenAndRdmChangesTheImage) {
  REQUIRE_VULKAN();
  const std::string scene = GetParam();
  Image8 with, without;
  Image hdr;
  ASSERT_TRUE(renderOffscreen(scene, "--frames 2", with, &hdr))
      << "rdm-viewer failed for " << scene;
  ASSERT_TRUE(renderOffscreen(scene, "--no-rdm", without));
  ASSERT_EQ(with.width, kWidth);
  ASSERT_EQ(hdr.width, kWidth);
  // Not blank: many distinct values, finite HDR.
  std::map<int, int> histogram;
  for (size_t i = 0; i < with.pixels.size(); i += 3) histogram[with.pixels[i] / 8]++;
  EXPECT_GT(histogram.size(), 12u);
  for (float v : hdr.pixels) ASSERT_TRUE(std::isfinite(v) && v >= 0.0f);
  expectMatchesGolden(scene + "_rdm", with);
  expectMatchesGolden(scene + "_flat", without);
  // With and without RDMs differ, most in the reflective regions: the polished board (chess)
  // and the mirror cube (island, camera 0: pixels 148..197 x 72..122 of 320 x 180).
  const ImageDiff whole = diffImages(with, without, 4);
  EXPECT_GT(whole.mean_abs, 1.0);
  EXPECT_GT(whole.frac_over, 0.10);
  if (scene == "island") {
    const ImageDiff mirror = diffImages(with, without, 16, 150, 75, 195, 120);
    EXPECT_GT(mirror.mean_abs, 10.0);
    EXPECT_GT(mirror.frac_over, 0.5);
  }
}

INSTANTIATE_TEST_SUITE_P(Viewer, ViewerOffscreen, testing::Values("chess", "island"));

// In-block reflections (viewer/shaders/near_voxels.glsl, term `in-block`): mirror_floor's floor
// reflects the blue bar standing inside its own block, which its RDM cannot see, only with the
// term on (it is part of the default); the sky above the scene is unchanged. Region: the bar's
// mirror image at 320 x 180.
TEST(ViewerInBlock, MirrorFloorReflectsWhatStandsInItsOwnBlock) {
  REQUIRE_VULKAN();
  Image8 with, without;
  ASSERT_TRUE(renderOffscreen("mirror_floor", "", with));
  ASSERT_TRUE(renderOffscreen(
      "mirror_floor", "--terms rdm,diffuse,specular,sun,shadows,emission,background,face-light",
      without));
  const int x0 = 172, y0 = 112, x1 = 190, y1 = 158;
  const ImageDiff reflection = diffImages(with, without, 16, x0, y0, x1, y1);
  EXPECT_GT(reflection.mean_abs, 20.0);
  EXPECT_GT(reflection.frac_over, 0.5);
  double blue_minus_red = 0.0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      const size_t i = (size_t(y) * with.width + x) * 3;
      blue_minus_red += double(with.pixels[i + 2]) - double(with.pixels[i]);
    }
  EXPECT_GT(blue_minus_red / ((x1 - x0) * (y1 - y0)), 40.0);  // the reflection is the bar's blue
  EXPECT_EQ(diffImages(with, without, 0, 0, 0, kWidth, 8).frac_over, 0.0);
}

TEST(ViewerCli, CompareRdmPrintsTableAndBadInputFailsCleanly) {
  REQUIRE_VULKAN();
  const std::string dir = testDir("cli");
  const std::string base =
      std::string(RDM_VIEWER_BINARY) + " --scene chess --width 64 --height 36 ";
  ASSERT_EQ(runCommand(base + "--atlas " + bakedAtlas("chess") + " --offscreen " + dir +
                           "/a.png --frames 3 --compare-rdm",
                       dir + "/table.txt"),
            0);
  const std::string text = fileText(dir + "/table.txt");
  EXPECT_NE(text.find("| with RDMs"), std::string::npos) << text;
  EXPECT_NE(text.find("| without RDMs"), std::string::npos) << text;
  EXPECT_NE(text.find("| with in-block"), std::string::npos) << text;  // on by default
  EXPECT_EQ(runCommand(base + "--camera 9 --offscreen " + dir + "/b.png"), 1);
  EXPECT_EQ(runCommand(base + "--atlas /nonexistent --offscreen " + dir + "/b.png"), 1);
  // Another scene's atlas is refused by name; no atlas says so instead of "RDM on".
  const std::string island = std::string(RDM_VIEWER_BINARY) +
                             " --scene island --width 64 --height 36 --offscreen " + dir + "/d.png";
  EXPECT_EQ(
      runCommand(island + " --atlas " + bakedAtlas("chess"), "/dev/null", dir + "/mismatch.txt"),
      1);
  EXPECT_NE(fileText(dir + "/mismatch.txt").find("was not baked from scene 'island'"),
            std::string::npos)
      << fileText(dir + "/mismatch.txt");
  ASSERT_EQ(runCommand(island, dir + "/none.txt"), 0);
  EXPECT_NE(fileText(dir + "/none.txt").find("RDM off (no atlas)"), std::string::npos)
      << fileText(dir + "/none.txt");
  EXPECT_EQ(
      runCommand(std::string(RDM_VIEWER_BINARY) + " --scene chesss --offscreen " + dir + "/e.png",
                 "/dev/null", dir + "/typo.txt"),
      1);
  EXPECT_NE(fileText(dir + "/typo.txt").find("neither a built-in scene"), std::string::npos);
  EXPECT_EQ(runCommand(base + "--frobnicate", "/dev/null", dir + "/unknown.txt"), 2);
  EXPECT_NE(fileText(dir + "/unknown.txt").find("unknown option '--frobnicate'"),
            std::string::npos);
  EXPECT_EQ(runCommand(base + "--bogus"), 2);
  // --version: the build id `rdm --version` prints (and the daemon records in its jobs).
  ASSERT_EQ(runCommand(std::string(RDM_VIEWER_BINARY) + " --version", dir + "/version.txt"), 0);
  ASSERT_EQ(runCommand(std::string(RDM_BINARY) + " --version", dir + "/rdm_version.txt"), 0);
  const std::string viewer_version = fileText(dir + "/version.txt");
  const std::string rdm_version = fileText(dir + "/rdm_version.txt");
  ASSERT_EQ(viewer_version.rfind("rdm-viewer rdm-cpu ", 0), 0u) << viewer_version;
  EXPECT_EQ(viewer_version.substr(std::string("rdm-viewer ").size()),
            rdm_version.substr(std::string("rdm ").size()));
  // --help: every option with its default, on stdout.
  ASSERT_EQ(runCommand(std::string(RDM_VIEWER_BINARY) + " --help", dir + "/help.txt"), 0);
  const std::string help = fileText(dir + "/help.txt");
  for (const char* want : {"--scene TEXT=chess", "=1280", "--aa", "--live-divisor", "--device"})
    EXPECT_NE(help.find(want), std::string::npos) << want << "\n" << help;
  // --device follows the core's policy (rdm/vulkan/vulkan_device.h), as `rdm bake --device` does.
  ASSERT_EQ(runCommand(base + "--device llvmpipe --offscreen " + dir + "/f.png", dir + "/dev.txt"),
            0);
  EXPECT_NE(fileText(dir + "/dev.txt").find("device: llvmpipe"), std::string::npos);
  EXPECT_EQ(runCommand(base + "--device 99 --offscreen " + dir + "/f.png", "/dev/null",
                       dir + "/dev99.txt"),
            1);
  EXPECT_NE(fileText(dir + "/dev99.txt").find("device index 99 out of range; devices: 0 '"),
            std::string::npos)
      << fileText(dir + "/dev99.txt");
  // No Vulkan driver: a clear error and exit 1, never a crash.
  EXPECT_EQ(
      runCommand("VK_ICD_FILENAMES=/nonexistent.json " + base + "--offscreen " + dir + "/c.png"),
      1);
}

// index.json's lighting fingerprint: an atlas baked before a 10x sun and a palette change is
// refused naming both; other bake settings alone (the tiny test bake) are only warned of.
TEST(ViewerCli, AtlasLitByAnotherSunOrPaletteIsRefusedNamingWhatDiffers) {
  REQUIRE_VULKAN();
  const std::string dir = testDir("lighting");
  ASSERT_FALSE(bakedAtlas("chess").empty());
  ASSERT_EQ(runCommand(std::string(RDM_BINARY) + " scene --scene chess -o " + dir + "/chess.json"),
            0);
  nlohmann::json scene = nlohmann::json::parse(fileText(dir + "/chess.json"));
  for (auto& c : scene["sun"]["irradiance"]) c = c.get<double>() * 10.0;
  scene["palette"][0]["color"] = {200, 40, 40};
  std::ofstream(dir + "/changed.json") << scene.dump();
  const std::string view = std::string(RDM_VIEWER_BINARY) +
                           " --width 32 --height 18 --frames 1 --offscreen " + dir + "/v.png" +
                           " --atlas " + bakedAtlas("chess") + " --scene ";
  EXPECT_EQ(runCommand(view + dir + "/changed.json", "/dev/null", dir + "/refused.txt"), 1);
  const std::string refused = fileText(dir + "/refused.txt");
  EXPECT_NE(refused.find("was lit by another palette, sun than scene"), std::string::npos)
      << refused;
  ASSERT_EQ(runCommand(view + dir + "/changed.json --allow-atlas-mismatch", dir + "/allowed.txt"),
            0);
  EXPECT_NE(fileText(dir + "/allowed.txt").find("atlas lit by another palette, sun"),
            std::string::npos);
  ASSERT_EQ(runCommand(view + "chess", dir + "/same.txt"), 0);
  const std::string same = fileText(dir + "/same.txt");
  EXPECT_NE(same.find("other bake settings"), std::string::npos) << same;
  EXPECT_EQ(same.find("lit by another"), std::string::npos) << same;
}

TEST(ViewerWindow, XvfbWindowRendersFramesAndTakesScreenshot) {
  REQUIRE_VULKAN();
  RDM_TEST_REQUIRE(runCommand("command -v xvfb-run") == 0, "xvfb-run is not installed");
  const std::string dir = testDir("window");
  const std::string cmd = "xvfb-run -a " + std::string(RDM_VIEWER_BINARY) +
                          " --scene chess --atlas " + bakedAtlas("chess") +
                          " --frames 5 --width 320 --height 180 --screenshot " + dir + "/shot.png";
  ASSERT_EQ(runCommand(cmd), 0) << cmd;
  Image8 shot, offscreen;
  ASSERT_TRUE(readPng(dir + "/shot.png", shot));
  EXPECT_EQ(shot.width, 320);
  EXPECT_EQ(shot.height, 180);
  // The window shows the scene camera's view: the same image as the offscreen render.
  ASSERT_TRUE(renderOffscreen("chess", "", offscreen));
  EXPECT_LE(diffImages(shot, offscreen, 24).mean_abs, 1.5);
}

}  // namespace
}  // namespace rdm::viewer

#endif  // RDM_VIEWER_BINARY
