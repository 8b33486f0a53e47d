// The compact packer (per-face tiles), index formats and atlas outputs (docs/spec.md
// section 4).
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <random>

#include "rdm/atlas/atlas.h"
#include "rdm/atlas/atlas_incremental.h"
#include "rdm/atlas/noise_map.h"
#include "rdm/base/file_util.h"
#include "rdm/image/exr_io.h"

namespace rdm {
namespace {

// Tiles lie inside their pages, aligned to their size, never overlap, and exactly the
// faces `stored` names are stored.
void expectValidLayout(const AtlasLayout& layout, size_t count, const StoredFaces& stored) {
  ASSERT_EQ(layout.entries.size(), count);
  std::vector<std::vector<uint8_t>> used;
  for (const AtlasPage& p : layout.pages) {
    ASSERT_LE(p.width, kMaxPageSize);
    ASSERT_LE(p.height, kMaxPageSize);
    used.emplace_back(size_t(p.width) * p.height, 0);
  }
  for (size_t i = 0; i < layout.entries.size(); ++i) {
    const AtlasEntry& e = layout.entries[i];
    if (i > 0) {
      ASSERT_TRUE(canonicalLess(layout.entries[i - 1].id, e.id));
    }
    ASSERT_EQ(e.storedMask(), stored(e.id.slot));
    ASSERT_TRUE(tilesFit(e, layout.pages));
    const int s = e.id.size;
    for (const FaceTile& t : e.faces) {
      if (!t.stored()) continue;
      ASSERT_EQ(t.x % s, 0);
      ASSERT_EQ(t.y % s, 0);
      const AtlasPage& p = layout.pages[size_t(t.page)];
      for (int y = t.y; y < t.y + s; ++y)
        for (int x = t.x; x < t.x + s; ++x)
          ASSERT_EQ(used[size_t(t.page)][size_t(y) * p.width + x]++, 0) << "overlap";
    }
  }
}

struct BuiltinRdms {
  Scene scene;
  VoxelWorld world;
  std::vector<RdmId> ids;
};

BuiltinRdms builtinRdms(const std::string& name) {
  BuiltinRdms b;
  b.scene = *builtinScene(name);
  b.world = buildWorld(b.scene);
  b.ids = listRdms(b.world, b.scene.bake);
  return b;
}

// Skipped faces take no space: stored tiles cover >= 95 % of the pages (the issue's target;
// the 2S x 3S rects of index version 1 left chess at 44 % and island at 48 % useful).
TEST(Atlas, BuiltinScenesPackAtLeast95PercentOfTexelsUseful) {
  for (const std::string name : {"chess", "island", "furnace", "terrain", "mirror_floor"}) {
    const BuiltinRdms b = builtinRdms(name);
    const StoredFaces stored = storedFacesOf(b.world);
    AtlasLayout layout = packCanonical(b.ids, stored);
    expectValidLayout(layout, b.ids.size(), stored);
    EXPECT_GE(layout.occupancy(), 0.95) << name;
    EXPECT_EQ(layout.pages.size(), 1u);
    std::printf("%s: %zu RDMs, page %d x %d, %.1f %% useful\n", name.c_str(), b.ids.size(),
                layout.pages[0].width, layout.pages[0].height, 100.0 * layout.occupancy());
  }
}

TEST(Atlas, PackingIsAPureFunctionOfTheRdmSet) {
  BuiltinRdms b = builtinRdms("island");
  AtlasLayout a = packCanonical(b.ids, storedFacesOf(b.world));
  std::shuffle(b.ids.begin(), b.ids.end(), std::mt19937(4));
  AtlasLayout c = packCanonical(b.ids, storedFacesOf(b.world));
  EXPECT_EQ(indexToJson(a), indexToJson(c));
}

TEST(Atlas, MixedSizesPackDenselyAndSpillToFurtherPages) {
  std::vector<RdmId> ids;
  for (int i = 0; i < 300; ++i) ids.push_back({{i % 256, i / 256, 0}, 0, 512});
  for (int i = 0; i < 3000; ++i) ids.push_back({{i % 256, i / 256, 1}, 7, 2});
  auto some = [](const glm::ivec3& s) { return FaceMask(kAllFaces & ~(1u << (s.x % 6))); };
  AtlasLayout layout = packCanonical(ids, some);
  expectValidLayout(layout, ids.size(), some);
  EXPECT_GE(layout.pages.size(), 2u);
  EXPECT_GE(layout.occupancy(), 0.9);
}

TEST(Atlas, AnRdmWithEveryFaceSkippedTakesNoSpace) {
  auto none = [](const glm::ivec3& s) { return s.x == 0 ? FaceMask(0) : kAllFaces; };
  AtlasLayout layout = packCanonical({{{0, 0, 0}, 7, 2}, {{1, 0, 0}, 7, 2}}, none);
  expectValidLayout(layout, 2, none);
  EXPECT_DOUBLE_EQ(layout.occupancy(), 1.0);  // six 2 x 2 tiles: 12 x 2 or 6 x 4 texels
}

TEST(Atlas, IndexJsonRoundTripsAndTextListsEveryTileOfPage0) {
  const BuiltinRdms b = builtinRdms("chess");
  AtlasLayout layout = packCanonical(b.ids, storedFacesOf(b.world));
  layout.scene_version = 3;
  auto parsed = parseIndexJson(indexToJson(layout));
  ASSERT_TRUE(parsed.ok()) << parsed.error();
  EXPECT_EQ(indexToJson(*parsed), indexToJson(layout));
  std::string text = indexToText(layout);
  std::istringstream in(text);
  int count, w, h;
  in >> count >> w >> h;
  EXPECT_EQ(size_t(count), layout.storedTiles());
  EXPECT_EQ(w, layout.pages[0].width);
  EXPECT_EQ(h, layout.pages[0].height);
  int i, j, k, level, face, x, y, size, lines = 0;
  while (in >> i >> j >> k >> level >> face >> x >> y >> size) {
    const AtlasEntry* e = layout.find({i, j, k}, level);
    ASSERT_NE(e, nullptr);
    ASSERT_TRUE(face >= 0 && face < 6);
    EXPECT_EQ(size, e->id.size);
    EXPECT_EQ(e->faces[size_t(face)], (FaceTile{0, x, y}));
    ++lines;
  }
  EXPECT_EQ(lines, count);
}

TEST(Atlas, IndexRefusesOtherFormatsVersion1AndTilesOutsideTheirPage) {
  EXPECT_FALSE(parseIndexJson("{\"format\": \"nope\"}").ok());
  auto v1 = parseIndexJson(R"({"format": "rdm-atlas", "version": 1, "pages": [], "rdms": []})");
  ASSERT_FALSE(v1.ok());
  EXPECT_NE(v1.error().find("version 1"), std::string::npos) << v1.error();
  EXPECT_NE(v1.error().find("bake the scene again"), std::string::npos) << v1.error();
  const std::string outside = R"({"format": "rdm-atlas", "version": 2,
      "pages": [{"width": 8, "height": 8}],
      "rdms": [{"slot": [0, 0, 0], "level": 7, "size": 4,
                "faces": [[0, 0, 0], [0, 4, 0], [0, 0, 4], [0, 4, 4], [0, 8, 0], null]}]})";
  auto bad = parseIndexJson(outside);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().find("rdms[0]"), std::string::npos) << bad.error();
  auto short_faces = parseIndexJson(R"({"format": "rdm-atlas", "version": 2, "pages": [],
      "rdms": [{"slot": [0, 0, 0], "level": 7, "size": 4, "faces": [null]}]})");
  EXPECT_FALSE(short_faces.ok());
}

TEST(Atlas, OutputsPlaceEveryStoredTexelAndRefuseNonFinite) {
  std::string dir = testing::TempDir() + "/atlas_out_" + std::to_string(getpid());
  std::filesystem::remove_all(dir);
  std::vector<RdmData> rdms(2);
  rdms[0].id = {{0, 0, 0}, 7, 2};
  rdms[1].id = {{1, 0, 0}, 3, 4};
  rdms[1].skipped[2] = rdms[1].skipped[5] = true;
  for (RdmData& d : rdms) {
    d.image = Image(2 * d.id.size, 3 * d.id.size, 4);
    for (size_t p = 0; p < d.image.pixels.size(); ++p)
      d.image.pixels[p] = float(p % 97) + d.id.slot.x + 1.0f;
  }
  AtlasLayout layout = packCanonical({rdms[0].id, rdms[1].id}, storedFacesOf(rdms));
  EXPECT_EQ(layout.find({1, 0, 0}, 3)->storedMask(), kAllFaces & ~0x24);
  EXPECT_DOUBLE_EQ(layout.occupancy(), 1.0);
  ASSERT_TRUE(writeAtlasOutputs(dir, layout, rdms).ok());
  auto atlas = readAtlasOutputs(dir);
  ASSERT_TRUE(atlas.ok()) << atlas.error();
  for (const RdmData& d : rdms) {
    const Image back = rdmTexels(*atlas, *atlas->layout.find(d.id.slot, d.id.level));
    const int s = d.id.size;
    for (int f = 0; f < 6; ++f)
      for (int j = 0; j < s; ++j)
        for (int i = 0; i < s; ++i)
          for (int c = 0; c < 4; ++c) {
            const int x = s * (f % 2) + i, y = s * (f / 2) + j;
            ASSERT_EQ(back.at(x, y, c), d.skipped[size_t(f)] ? 0.0f : d.image.at(x, y, c));
          }
  }
  std::string bad_dir = testing::TempDir() + "/atlas_bad_" + std::to_string(getpid());
  std::filesystem::remove_all(bad_dir);
  rdms[1].image.at(1, 1, 2) = NAN;
  Status s = writeAtlasOutputs(bad_dir, layout, rdms);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("non-finite"), std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(bad_dir + "/atlas.exr"));
}

// atlas.exr and noise.exr byte for byte on 1 and on 3 of OpenEXR's threads, float32 and
// half radiance: 96 RDMs of S = 16 with noisy texels, pages of many 16-row ZIP chunks.
TEST(Atlas, PagesAndNoiseMapsDoNotDependOnCompressionThreads) {
  std::vector<RdmData> rdms(96);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.01f, 50.0f);
  for (size_t r = 0; r < rdms.size(); ++r) {
    RdmData& d = rdms[r];
    d.id = {{int(r % 8), int(r / 8), 0}, 2, 16};
    d.image = Image(32, 48, 4);
    for (float& p : d.image.pixels) p = u(rng);
    d.stderr_rgb.resize(d.image.pixels.size() / 4 * 3);
    for (float& e : d.stderr_rgb) e = 0.01f * u(rng);
  }
  std::vector<RdmId> ids;
  for (const RdmData& d : rdms) ids.push_back(d.id);
  const std::string base = testing::TempDir() + "/atlas_threads_" + std::to_string(getpid());
  for (RadianceFormat format : {RadianceFormat::kFloat32, RadianceFormat::kHalf}) {
    const AtlasLayout layout = packCanonical(ids, storedFacesOf(rdms), format);
    ASSERT_GE(layout.pages[0].height, 64);
    std::string first[2];
    for (int threads : {1, 3}) {
      setExrThreads(threads);
      const std::string dir = base + "_" + std::to_string(threads);
      std::filesystem::remove_all(dir);
      ASSERT_TRUE(writeAtlasOutputs(dir, layout, rdms).ok());
      ASSERT_TRUE(writeNoiseMaps(dir, layout, MemoryRdmSource(rdms)).ok());
      const std::string files[2] = {dir + "/atlas.exr", dir + "/noise.exr"};
      for (int f = 0; f < 2; ++f) {
        auto bytes = readFileToString(files[f]);
        ASSERT_TRUE(bytes.ok()) << bytes.error();
        if (threads == 1) first[f] = *bytes;
        EXPECT_EQ(*bytes, first[f]) << files[f] << " " << radianceFormatName(format);
      }
      std::filesystem::remove_all(dir);
    }
  }
  setExrThreads(0);
}

// Half radiance: every R, G, B comes back within half's rounding (relative 2^-11, tolerance
// stated as 2^-11 of the value), a sun-lit face of 1e6 stays finite through its tile's
// exponent, Z is float32 exactly, and the pages are smaller than float32 ones.
TEST(Atlas, HalfRadianceKeepsValuesAbove65504AndDepthExact) {
  const std::string base = testing::TempDir() + "/atlas_half_" + std::to_string(getpid());
  std::vector<RdmData> rdms(2);
  rdms[0].id = {{0, 0, 0}, 0, 8};
  rdms[1].id = {{1, 0, 0}, 7, 8};
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (RdmData& d : rdms) {
    d.image = Image(16, 24, 4);
    for (int y = 0; y < 24; ++y)
      for (int x = 0; x < 16; ++x) {
        const bool sunlit = d.id.level == 0 && x < 8 && y < 8;  // face 0 of the mirror RDM
        for (int c = 0; c < 3; ++c)
          d.image.at(x, y, c) = sunlit ? 1.0e6f * (0.5f + u(rng)) : 1e-3f + 20.0f * u(rng);
        d.image.at(x, y, 3) = 3.0f + 0.123456789f * float(x + 16 * y);
      }
  }
  AtlasLayout layout = packCanonical({rdms[0].id, rdms[1].id}, storedFacesOf(rdms));
  ASSERT_TRUE(writeAtlasOutputs(base + "_float", layout, rdms).ok());
  layout.radiance = RadianceFormat::kHalf;
  Status written = writeAtlasOutputs(base + "_half", layout, rdms);
  ASSERT_TRUE(written.ok()) << written.message();
  auto atlas = readAtlasOutputs(base + "_half");
  ASSERT_TRUE(atlas.ok()) << atlas.error();
  EXPECT_EQ(atlas->layout.radiance, RadianceFormat::kHalf);
  EXPECT_EQ(atlas->layout.find({0, 0, 0}, 0)->faces[0].exponent, 5);  // 1.5e6 / 2^5 <= 65504
  EXPECT_EQ(atlas->layout.find({1, 0, 0}, 7)->faces[0].exponent, 0);
  for (const RdmData& d : rdms) {
    const Image back = rdmTexels(*atlas, *atlas->layout.find(d.id.slot, d.id.level));
    for (int y = 0; y < 24; ++y)
      for (int x = 0; x < 16; ++x) {
        for (int c = 0; c < 3; ++c) {
          const float v = d.image.at(x, y, c);
          ASSERT_NEAR(back.at(x, y, c), v, v * 0x1p-11f) << x << "," << y;
        }
        ASSERT_EQ(back.at(x, y, 3), d.image.at(x, y, 3));
      }
  }
  const auto bytes = [](const std::string& dir) {
    return std::filesystem::file_size(dir + "/atlas.exr");
  };
  EXPECT_LT(bytes(base + "_half"), bytes(base + "_float"));
  auto unknown = parseIndexJson(R"({"format": "rdm-atlas", "version": 2, "radiance": "bf16",
      "pages": [], "rdms": []})");
  ASSERT_FALSE(unknown.ok());
  EXPECT_NE(unknown.error().find("bf16"), std::string::npos) << unknown.error();
}

// An edit that un-skips a face: the other faces keep their tiles, the new face gets free
// space, a face that became skipped frees its tile.
TEST(Atlas, IncrementalKeepsStoredTilesAndPlacesNewlyStoredFaces) {
  std::vector<RdmId> ids;
  for (int i = 0; i < 20; ++i) ids.push_back({{i, 0, 0}, 7, 2 << (i % 3)});
  auto before = [](const glm::ivec3& s) { return FaceMask(s.x == 3 ? 0x1f : kAllFaces); };
  auto after = [](const glm::ivec3& s) { return FaceMask(s.x == 5 ? 0x3e : kAllFaces); };
  const AtlasLayout base = packCanonical(ids, before);
  const AtlasLayout next = packIncremental(base, ids, after);
  expectValidLayout(next, ids.size(), after);
  for (const AtlasEntry& e : next.entries) {
    const AtlasEntry* old = base.find(e.id.slot, e.id.level);
    for (int f = 0; f < 6; ++f) {
      if (old->faces[size_t(f)].stored() && e.faces[size_t(f)].stored()) {
        EXPECT_EQ(e.faces[size_t(f)], old->faces[size_t(f)]) << e.id.slot.x << " face " << f;
      }
    }
  }
}

TEST(Atlas, IncrementalKeepsTilesAndPlacesNewRdmsInFreeSpace) {
  std::vector<RdmId> base_ids, next_ids;
  for (int i = 0; i < 40; ++i) {
    RdmId id{{i % 7, i / 7, 0}, i % 3 == 0 ? 2 : 7, i % 3 == 0 ? 64 : 2};
    base_ids.push_back(id);
    if (i % 5 != 0) next_ids.push_back(id);  // some go away
  }
  for (int i = 0; i < 12; ++i)
    next_ids.push_back({{i, 9, 1}, i % 2 ? 0 : 7, i % 2 ? 32 : 2});  // new ones
  auto stored = [](const glm::ivec3& s) { return FaceMask(s.z == 1 ? 0x0f : kAllFaces); };
  const AtlasLayout base = packCanonical(base_ids, stored);
  const AtlasLayout next = packIncremental(base, next_ids, stored);
  expectValidLayout(next, next_ids.size(), stored);
  for (const AtlasEntry& e : next.entries) {
    if (const AtlasEntry* old = base.find(e.id.slot, e.id.level)) {
      EXPECT_EQ(old->faces, e.faces);
    }
  }
}

}  // namespace
}  // namespace rdm
