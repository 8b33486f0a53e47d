// The bc6h atlas (docs/spec.md section 4, docs/bc6h.md): block-aligned packing, the files
// written, radiance within the codec's error of the float32 atlas, depth at half precision,
// bright tiles through the tile exponent, and truncated pages refused naming the file.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "atlas_error.h"
#include "rdm/atlas/atlas.h"
#include "rdm/atlas/atlas_incremental.h"
#include "rdm/bake/bake.h"
#include "rdm/scene/scene.h"
#include "rdm/scene/world.h"

namespace rdm {
namespace {

namespace fs = std::filesystem;

std::string freshDir(const std::string& name) {
  const std::string dir = testing::TempDir() + "/atlas_bc6h_" + std::to_string(getpid()) + name;
  fs::remove_all(dir);
  return dir;
}

// Tiles of sizes 32 down to 1 (S = 2 and 1 exist), some faces skipped.
std::vector<RdmId> mixedSizes() {
  std::vector<RdmId> ids;
  for (int i = 0; i < 60; ++i) ids.push_back({{i % 5, i / 5, 0}, i % 7, 1 << (i % 6)});
  return ids;
}

FaceMask someFaces(const glm::ivec3& slot) {
  return FaceMask(slot.x == 2 ? 0x2d : kAllFaces);
}

TEST(AtlasBc6h, PackerAlignsTilesToBlocksAndLeavesOtherFormatsAlone) {
  const AtlasLayout plain = packCanonical(mixedSizes(), someFaces);
  const AtlasLayout half = packCanonical(mixedSizes(), someFaces, RadianceFormat::kHalf);
  EXPECT_EQ(half.pages.size(), plain.pages.size());
  for (size_t i = 0; i < plain.entries.size(); ++i)
    EXPECT_EQ(half.entries[i].faces, plain.entries[i].faces) << i;
  EXPECT_FALSE(blockAligned(plain));  // S = 1 and 2 tiles share blocks
  const AtlasLayout bc6h = packCanonical(mixedSizes(), someFaces, RadianceFormat::kBc6h);
  EXPECT_EQ(bc6h.radiance, RadianceFormat::kBc6h);
  EXPECT_TRUE(blockAligned(bc6h));
  for (const AtlasPage& p : bc6h.pages) {
    EXPECT_EQ(p.width % kBc6hTileAlign, 0);
    EXPECT_EQ(p.height % kBc6hTileAlign, 0);
  }
  for (const AtlasEntry& e : bc6h.entries) {
    EXPECT_TRUE(tilesFit(e, bc6h.pages));
    EXPECT_EQ(e.storedMask(), someFaces(e.id.slot));
  }
}

std::vector<RdmData> bakeChess() {
  const Scene scene = builtinScene("chess").value();
  BakeSettings settings = scene.bake;
  settings.spp = 4, settings.max_hemisphere = 16;
  return bakeScene(buildWorld(scene), settings, BakeOptions{}).rdms;
}

// `rdms` packed for `format` (as rdm bake packs them), written and read back.
Expected<LoadedAtlas> writeAndRead(const std::string& dir, RadianceFormat format,
                                   const std::vector<RdmData>& rdms) {
  std::vector<RdmId> ids;
  for (const RdmData& d : rdms) ids.push_back(d.id);
  const AtlasLayout layout = packCanonical(ids, storedFacesOf(rdms), format);
  if (Status s = writeAtlasOutputs(dir, layout, rdms); !s) return s;
  return readAtlasOutputs(dir);
}

// Chess at S <= 16 and 4 spp (the same RDMs): the bc6h atlas reads back within the codec's
// error of the float32 one, over values above 1e-3: mean relative error < 1.5 %, p99 < 10 %
// (measured 0.82 % and 7.1 %; noisy 4-spp tiles are harder for a block's one or two
// endpoint pairs than the default bake's, where docs/bc6h.md measured 0.28 % and 3.3 %), and
// its depth within half's rounding (2^-11 relative).
TEST(AtlasBc6h, ChessReadsBackNearTheFloatAtlas) {
  const std::vector<RdmData> chess = bakeChess();
  const std::string f32_dir = freshDir("_f32"), bc6h_dir = freshDir("_bc6h");
  auto f32 = writeAndRead(f32_dir, RadianceFormat::kFloat32, chess);
  ASSERT_TRUE(f32.ok()) << f32.error();
  auto bc6h = writeAndRead(bc6h_dir, RadianceFormat::kBc6h, chess);
  ASSERT_TRUE(bc6h.ok()) << bc6h.error();
  EXPECT_TRUE(fs::exists(bc6h_dir + "/atlas.ktx2"));
  EXPECT_TRUE(fs::exists(bc6h_dir + "/depth.exr"));
  EXPECT_FALSE(fs::exists(bc6h_dir + "/atlas.exr"));
  EXPECT_EQ(bc6h->layout.radiance, RadianceFormat::kBc6h);
  EXPECT_TRUE(blockAligned(bc6h->layout));
  const test::AtlasError e = test::atlasError(*f32, *bc6h, 1e-3f);
  std::printf("[ bc6h ] chess S<=16: %zu values, mean relative %.3f %%, p99 %.3f %%, depth %.2e\n",
              e.values, 100.0 * e.mean, 100.0 * e.p99, e.max_depth_relative);
  EXPECT_GT(e.values, size_t(10000));
  EXPECT_LT(e.mean, 0.015);
  EXPECT_LT(e.p99, 0.10);
  EXPECT_LE(e.max_depth_relative, std::ldexp(1.0, -11));
  fs::remove_all(f32_dir);
  fs::remove_all(bc6h_dir);
}

// A sun-lit mirror's values (1e6, beyond BC6H's 65504) come back through the tile exponent.
TEST(AtlasBc6h, RadianceAbove65504Survives) {
  std::vector<RdmData> chess = bakeChess();
  std::vector<float>& bright = chess[0].image.pixels;
  for (size_t i = 0; i < bright.size(); ++i) bright[i] *= i % 4 == 3 ? 1.0f : 1e6f;
  const std::string f32_dir = freshDir("_bright_f32"), bc6h_dir = freshDir("_bright_bc6h");
  auto f32 = writeAndRead(f32_dir, RadianceFormat::kFloat32, chess);
  auto bc6h = writeAndRead(bc6h_dir, RadianceFormat::kBc6h, chess);
  ASSERT_TRUE(f32.ok() && bc6h.ok()) << (bc6h.ok() ? f32.error() : bc6h.error());
  const AtlasEntry* e = bc6h->layout.find(chess[0].id.slot, chess[0].id.level);
  ASSERT_NE(e, nullptr);
  int scaled = 0;
  for (const FaceTile& t : e->faces) scaled += t.exponent > 0;
  EXPECT_GT(scaled, 0);
  const Image want = rdmTexels(*f32, *f32->layout.find(e->id.slot, e->id.level));
  const Image got = rdmTexels(*bc6h, *e);
  double largest = 0.0, sum_relative = 0.0;
  size_t values = 0;
  for (size_t p = 0; p < want.pixels.size() / 4; ++p)
    for (size_t c = 0; c < 3; ++c) {
      const double a = want.pixels[p * 4 + c], b = got.pixels[p * 4 + c];
      ASSERT_TRUE(std::isfinite(b));
      largest = std::max(largest, b);
      if (a > 1e3) sum_relative += std::abs(b - a) / a, ++values;
    }
  EXPECT_GT(largest, 65504.0);
  ASSERT_GT(values, size_t(0));
  EXPECT_LT(sum_relative / double(values), 0.01);
  fs::remove_all(f32_dir);
  fs::remove_all(bc6h_dir);
}

void truncateFile(const std::string& path, uintmax_t bytes) {
  fs::resize_file(path, bytes);
}

TEST(AtlasBc6h, TruncatedOrMissingPagesAreRefusedNamingTheFile) {
  const std::vector<RdmData> chess = bakeChess();
  const std::string dir = freshDir("_cut");
  auto atlas = writeAndRead(dir, RadianceFormat::kBc6h, chess);
  ASSERT_TRUE(atlas.ok()) << atlas.error();
  truncateFile(dir + "/atlas.ktx2", fs::file_size(dir + "/atlas.ktx2") / 2);
  auto cut = readAtlasOutputs(dir);
  ASSERT_FALSE(cut.ok());
  EXPECT_NE(cut.error().find(dir + "/atlas.ktx2"), std::string::npos) << cut.error();
  auto again = writeAndRead(dir, RadianceFormat::kBc6h, chess);
  ASSERT_TRUE(again.ok()) << again.error();
  fs::remove(dir + "/depth.exr");
  auto no_depth = readAtlasOutputs(dir);
  ASSERT_FALSE(no_depth.ok());
  EXPECT_NE(no_depth.error().find("depth.exr"), std::string::npos) << no_depth.error();
  fs::remove_all(dir);
}

// An incremental bc6h layout stays block-aligned and keeps a bc6h base's tiles; a base in
// another format keeps none (its small tiles may share blocks): the canonical packing.
TEST(AtlasBc6h, IncrementalPackingStaysBlockAligned) {
  const AtlasLayout base = packCanonical(mixedSizes(), someFaces, RadianceFormat::kBc6h);
  std::vector<RdmId> grown = mixedSizes();
  for (int i = 0; i < 20; ++i) grown.push_back({{i, 9, 1}, 7, 2});  // twenty new S = 2 RDMs
  const AtlasLayout next = packIncremental(base, grown, someFaces, RadianceFormat::kBc6h);
  EXPECT_EQ(next.radiance, RadianceFormat::kBc6h);
  EXPECT_TRUE(blockAligned(next));
  for (const AtlasEntry& old : base.entries)
    EXPECT_EQ(next.find(old.id.slot, old.id.level)->faces, old.faces);
  const AtlasLayout from_plain = packIncremental(packCanonical(mixedSizes(), someFaces), grown,
                                                 someFaces, RadianceFormat::kBc6h);
  EXPECT_TRUE(blockAligned(from_plain));
  const AtlasLayout canonical = packCanonical(grown, someFaces, RadianceFormat::kBc6h);
  ASSERT_EQ(from_plain.entries.size(), canonical.entries.size());
  for (size_t i = 0; i < canonical.entries.size(); ++i)
    EXPECT_EQ(from_plain.entries[i].faces, canonical.entries[i].faces) << i;
}

// A page of flat tiles, one value per tile, on a block-aligned layout of two RDMs.
struct TwoTiles {
  AtlasLayout layout;
  Image texels{16, 8, 4};
  TwoTiles(float first, float second) {
    layout.radiance = RadianceFormat::kBc6h;
    layout.pages = {{16, 8}};
    AtlasEntry a, b;
    a.id = {{0, 0, 0}, 0, 8}, b.id = {{1, 0, 0}, 0, 8};
    a.faces[0] = {0, 0, 0, 0}, b.faces[0] = {0, 8, 0, 0};
    layout.entries = {a, b};
    for (int y = 0; y < 8; ++y)
      for (int x = 0; x < 16; ++x)
        for (int c = 0; c < 3; ++c) texels.at(x, y, c) = (x < 8 ? first : second) * float(c + 1);
  }
};

Bc6hReuse reuseOf(const TwoTiles& base, const Bc6hImage& base_blocks, bool second_rebaked) {
  Bc6hReuse reuse;
  reuse.base = base.layout;
  reuse.base_page = [base_blocks](int) -> Expected<Bc6hImage> { return base_blocks; };
  reuse.rebaked = [second_rebaked](const RdmId& id) { return second_rebaked && id.slot.x == 1; };
  return reuse;
}

// A kept tile's blocks are the base's bytes, a re-baked tile's are encoded from the new
// texels; when the base holds what a whole encode gives, the page is byte for byte a whole
// encode's (blocks are encoded independently). Each of the two tiles is 2 x 2 blocks.
TEST(AtlasBc6h, IncrementalPagesEncodeOnlyTheTilesTheyRebake) {
  const TwoTiles before(1.0f, 2.0f), after(5.0f, 7.0f);
  auto base_blocks = encodeBc6h(before.texels);
  auto whole_after = encodeBc6h(after.texels);
  ASSERT_TRUE(base_blocks.ok() && whole_after.ok());
  Bc6hReuse reuse = reuseOf(before, *base_blocks, true);
  auto mixed = encodeBc6hReusing(after.layout, 0, after.texels, {}, reuse);
  ASSERT_TRUE(mixed.ok()) << mixed.error();
  EXPECT_EQ(reuse.reused_blocks, 4u);
  EXPECT_EQ(reuse.encoded_blocks, 4u);
  auto decoded = decodeBc6h(*mixed);
  ASSERT_TRUE(decoded.ok());
  EXPECT_NEAR(decoded->at(3, 3, 0), 1.0f, 0.01f);   // kept: the base's value
  EXPECT_NEAR(decoded->at(12, 3, 0), 7.0f, 0.07f);  // re-baked: the new one
  Bc6hReuse same = reuseOf(after, *whole_after, false);
  auto copied = encodeBc6hReusing(after.layout, 0, after.texels, {}, same);
  ASSERT_TRUE(copied.ok());
  EXPECT_EQ(same.reused_blocks, 8u);
  EXPECT_EQ(copied->blocks, whole_after->blocks);
  Bc6hReuse none = reuseOf(after, *whole_after, false);
  none.base.entries[0].faces[0].exponent = 1;  // another scale: not the same tile
  none.base.entries[1].faces[0].x = 0;         // another place
  auto encoded = encodeBc6hReusing(after.layout, 0, after.texels, {}, none);
  ASSERT_TRUE(encoded.ok());
  EXPECT_EQ(none.reused_blocks, 0u);
  EXPECT_EQ(encoded->blocks, whole_after->blocks);
}

}  // namespace
}  // namespace rdm
