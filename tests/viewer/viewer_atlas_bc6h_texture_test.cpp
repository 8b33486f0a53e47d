// The viewer's kBc6h atlas texture (viewer/renderer/atlas_texture_bc6h.cpp, docs/bc6h.md):
// a bc6h atlas's blocks go to the device as they are, Z as half beside them; rects written
// later are encoded on the CPU and keep the texels they share blocks with. Built with the
// viewer only; every test needs a device that samples BC6H (lavapipe does).
#include <gtest/gtest.h>

#ifdef RDM_VIEWER_BINARY
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "atlas_texture.h"
#include "rdm/atlas/atlas.h"
#include "rdm/image/exr_io.h"
#include "rdm/image/flip.h"
#include "rdm/image/tonemap.h"
#include "renderer.h"
#include "test_requirements.h"

namespace rdm::viewer {
namespace {

namespace fs = std::filesystem;

#define REQUIRE_BC6H(context)                                                                     \
  RDM_TEST_REQUIRE((context).ok(),                                                                \
                   "no Vulkan device: " << ((context).ok() ? std::string() : (context).error())); \
  RDM_TEST_REQUIRE((*(context))->samplesBc6h(), "the Vulkan device does not sample BC6H")

std::string freshDir(const std::string& name) {
  const std::string dir =
      testing::TempDir() + "/viewer_bc6h_texture_" + std::to_string(getpid()) + "_" + name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

int run(const std::string& cmd, const std::string& log) {
  const int status = std::system((cmd + " > " + log + " 2>&1").c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// Chess at a small budget in bc6h, into dir/atlas.
void bakeChessBc6h(const std::string& dir) {
  ASSERT_EQ(run(std::string(RDM_BINARY) +
                    " bake --scene chess --spp 4 --max-hemisphere 16 --max-bounces 2 --seed 3 "
                    "--quiet --radiance bc6h -o " +
                    dir + "/atlas",
                dir + "/bake.log"),
            0);
}

// A constant rect of R, G, B = `value` and Z = `depth`.
Image constantRect(int w, int h, float value, float depth) {
  Image rect(w, h, 4);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      for (int c = 0; c < 3; ++c) rect.at(x, y, c) = value * float(c + 1);
      rect.at(x, y, 3) = depth;
    }
  return rect;
}

bool inside(int x, int y, int rx, int ry, int rw, int rh) {
  return x >= rx && x < rx + rw && y >= ry && y < ry + rh;
}

// The layer holds the file's blocks decoded (the same decoder the atlas readers use) and Z
// at half, bit for bit; tiles with a scale exponent are re-encoded (none in chess).
TEST(ViewerAtlasBc6hTexture, HoldsTheFilesBlocksAndDepthAsTheyAre) {
  auto context = VulkanContext::create({});
  REQUIRE_BC6H(context);
  const std::string dir = freshDir("blocks");
  bakeChessBc6h(dir);
  auto layout = readAtlasLayout(dir + "/atlas");
  ASSERT_TRUE(layout.ok()) << layout.error();
  auto texture = AtlasTexture::create(**context, layout->pages, AtlasPrecision::kBc6h);
  ASSERT_TRUE(texture.ok()) << texture.error();
  AtlasTexture& t = **texture;
  EXPECT_EQ(t.format(), VK_FORMAT_BC6H_UFLOAT_BLOCK);
  EXPECT_EQ(t.texelBytes(), 3u);
  ASSERT_TRUE(loadAtlasPages(dir + "/atlas", *layout, t).ok());
  auto page = readBc6hAtlasPage(dir + "/atlas", *layout, 0);
  ASSERT_TRUE(page.ok()) << page.error();
  auto back = t.readLayer(0);
  ASSERT_TRUE(back.ok()) << back.error();
  size_t texels_with_depth = 0;
  for (const AtlasEntry& e : layout->entries)
    for (const FaceTile& tile : e.faces) {
      if (tile.page != 0) continue;
      ASSERT_EQ(tile.exponent, 0);
      for (int y = tile.y; y < tile.y + e.id.size; ++y)
        for (int x = tile.x; x < tile.x + e.id.size; ++x) {
          for (int c = 0; c < 4; ++c)
            ASSERT_EQ(back->at(x, y, c), page->at(x, y, c)) << x << "," << y;
          ASSERT_EQ(t.depthMask().any(0, x, y, 1, 1), page->at(x, y, 3) != 0.0f);
          texels_with_depth += page->at(x, y, 3) != 0.0f;
        }
    }
  EXPECT_GT(texels_with_depth, 1000u);
  EXPECT_EQ(t.deviceBytes(), size_t(t.width()) * size_t(t.height()) * 3);
  fs::remove_all(dir);
}

// Tiles stored scaled by 2^-e hold their radiance restored on the device: 1000 stored with
// e = 3 reads 8000 (within 1 %, BC6H's error of a flat block re-encoded), with e = 8 it is
// clamped to half's largest value as the half texture clamps it; an unscaled tile is as stored.
TEST(ViewerAtlasBc6hTexture, ScaledTilesAreRestoredAndClamped) {
  auto context = VulkanContext::create({});
  REQUIRE_BC6H(context);
  const std::string dir = freshDir("scaled");
  AtlasLayout layout;
  layout.radiance = RadianceFormat::kBc6h;
  layout.pages = {{24, 8}};
  AtlasEntry entry;
  entry.id.size = 8;
  entry.faces[0] = {0, 0, 0, 3};
  entry.faces[1] = {0, 8, 0, 8};
  entry.faces[2] = {0, 16, 0, 0};
  layout.entries.push_back(entry);
  Image page = constantRect(24, 8, 1000.0f, 2.0f);
  ASSERT_TRUE(writeBc6hAtlasPage(dir, layout, 0, page).ok());
  auto texture = AtlasTexture::create(**context, layout.pages, AtlasPrecision::kBc6h);
  ASSERT_TRUE(texture.ok()) << texture.error();
  ASSERT_TRUE(loadAtlasPages(dir, layout, **texture).ok());
  auto back = (*texture)->readLayer(0);
  ASSERT_TRUE(back.ok()) << back.error();
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 24; ++x)
      for (int c = 0; c < 3; ++c) {
        const float stored = 1000.0f * float(c + 1);
        const float want = x < 8 ? stored * 8.0f : x < 16 ? kAtlasHalfMax : stored;
        ASSERT_NEAR(back->at(x, y, c), want, 0.01f * want) << x << "," << y << "," << c;
        ASSERT_EQ(back->at(x, y, 3), 2.0f);
      }
  fs::remove_all(dir);
}

// Rects that do not fill their 4 x 4 blocks: their texels within 2 % (BC6H's endpoint
// quantisation on blocks of two colours), the blocks' other texels kept, Z exact at half; growing
// the image copies both images on the device.
TEST(ViewerAtlasBc6hTexture, RectsKeepTheTexelsTheyShareBlocksWith) {
  auto context = VulkanContext::create({});
  REQUIRE_BC6H(context);
  auto texture =
      AtlasTexture::create(**context, std::vector<AtlasPage>{{38, 30}}, AtlasPrecision::kBc6h);
  ASSERT_TRUE(texture.ok()) << texture.error();
  AtlasTexture& t = **texture;
  EXPECT_EQ(t.width() % 4, 0);
  EXPECT_EQ(t.height() % 4, 0);
  // Every block holds at most two colours; the second rect shares blocks 8..11 with the first.
  ASSERT_TRUE(t.applyDelta({{0, 6, 4, constantRect(5, 8, 1.5f, 3.25f)}}).ok());
  ASSERT_TRUE(t.applyDelta({{0, 11, 4, constantRect(6, 8, 40.0f, 0.5f)}}).ok());
  EXPECT_FALSE(t.applyDelta({{0, 36, 0, constantRect(4, 4, 1.0f, 1.0f)}}).ok());  // leaves the page
  auto check = [&](const Image& back, const char* when) {
    for (int y = 0; y < 30; ++y)
      for (int x = 0; x < 38; ++x) {
        const bool first = inside(x, y, 6, 4, 5, 8), second = inside(x, y, 11, 4, 6, 8);
        const float value = first ? 1.5f : second ? 40.0f : 0.0f;
        for (int c = 0; c < 3; ++c)
          ASSERT_NEAR(back.at(x, y, c), value * float(c + 1), 0.02f * value * float(c + 1) + 1e-6f)
              << when << " " << x << "," << y << "," << c;
        ASSERT_EQ(back.at(x, y, 3), first ? 3.25f : second ? 0.5f : 0.0f) << when << x << "," << y;
      }
  };
  auto back = t.readLayer(0);
  ASSERT_TRUE(back.ok()) << back.error();
  check(*back, "written");
  EXPECT_TRUE(t.depthMask().any(0, 6, 4, 1, 1));
  EXPECT_FALSE(t.depthMask().any(0, 0, 0, 6, 4));
  auto grown = AtlasTexture::create(**context, std::vector<AtlasPage>{{38, 90}, {8, 8}},
                                    AtlasPrecision::kBc6h);
  ASSERT_TRUE(grown.ok()) << grown.error();
  ASSERT_TRUE((*grown)->copyPagesFrom(t).ok());
  auto copied = (*grown)->readLayer(0);
  ASSERT_TRUE(copied.ok()) << copied.error();
  check(*copied, "copied");
  for (int y = 30; y < 90; ++y) ASSERT_EQ(copied->at(20, y, 0), 0.0f);
  EXPECT_TRUE((*grown)->depthMask().any(0, 11, 4, 1, 1));
  auto half = AtlasTexture::create(**context, std::vector<AtlasPage>{{38, 30}});
  ASSERT_TRUE(half.ok());
  EXPECT_FALSE((*half)->copyPagesFrom(t).ok());  // no copy between formats
}

// rdm-viewer on a bc6h atlas with --bc6h-texture stored and decoded: the frames agree within
// HDR-FLIP 1e-4 (measured 0 on chess: lavapipe's BC6H decoder and ours give the same halves).
TEST(ViewerAtlasBc6hTexture, StoredBlocksShowTheDecodedFrame) {
  auto context = VulkanContext::create({});
  REQUIRE_BC6H(context);
  const std::string dir = freshDir("frame");
  bakeChessBc6h(dir);
  for (const char* mode : {"stored", "decoded"}) {
    const std::string view = std::string(RDM_VIEWER_BINARY) + " --scene chess --atlas " + dir +
                             "/atlas --width 160 --height 90 --offscreen " + dir + "/" + mode +
                             ".png --exr " + dir + "/" + mode + ".exr --bc6h-texture " + mode;
    ASSERT_EQ(run(view, dir + "/" + mode + ".log"), 0) << mode;
    std::ifstream log(dir + "/" + mode + ".log");
    const std::string text((std::istreambuf_iterator<char>(log)), std::istreambuf_iterator<char>());
    EXPECT_NE(text.find(std::string("atlas texture: ") +
                        (std::string(mode) == "stored" ? "bc6h" : "half")),
              std::string::npos)
        << text;
  }
  auto stored = readFiniteExr(dir + "/stored.exr", kRgbChannels);
  auto decoded = readFiniteExr(dir + "/decoded.exr", kRgbChannels);
  ASSERT_TRUE(stored.ok() && decoded.ok());
  const double hdr = computeHdrFlip(*decoded, *stored).mean;
  std::printf("[ viewer ] bc6h stored vs decoded texture, chess 160x90: HDR-FLIP %.6f\n", hdr);
  EXPECT_LE(hdr, 1e-4);
  fs::remove_all(dir);
}

// A truncated atlas.ktx2: rdm-viewer exits non-zero with a message naming the file, whether it
// keeps the blocks or decodes them.
TEST(ViewerAtlasBc6hTexture, ATruncatedPageIsAClearError) {
  auto context = VulkanContext::create({});
  REQUIRE_BC6H(context);
  const std::string dir = freshDir("cut");
  bakeChessBc6h(dir);
  const std::string ktx2 = dir + "/atlas/atlas.ktx2";
  fs::resize_file(ktx2, fs::file_size(ktx2) / 2);
  for (const char* mode : {"stored", "decoded"}) {
    const std::string log = dir + "/" + mode + ".log";
    EXPECT_NE(run(std::string(RDM_VIEWER_BINARY) + " --scene chess --atlas " + dir +
                      "/atlas --width 64 --height 36 --offscreen " + dir + "/out.png" +
                      " --bc6h-texture " + mode,
                  log),
              0)
        << mode;
    std::ifstream in(log);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_NE(text.find("atlas.ktx2"), std::string::npos) << mode << ": " << text;
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rdm::viewer
#endif  // RDM_VIEWER_BINARY
