// The canonical packer, index formats and atlas outputs (docs/spec.md section 4).
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <random>

#include "rdm/atlas.h"
#include "rdm/exr_io.h"
#include "rdm/file_util.h"

namespace rdm {
namespace {

void expectValidLayout(const AtlasLayout& layout, size_t count) {
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
    const AtlasPage& p = layout.pages[e.page];
    ASSERT_LE(e.x + 2 * e.id.size, p.width);
    ASSERT_LE(e.y + 3 * e.id.size, p.height);
    for (int y = e.y; y < e.y + 3 * e.id.size; ++y)
      for (int x = e.x; x < e.x + 2 * e.id.size; ++x)
        ASSERT_EQ(used[e.page][size_t(y) * p.width + x]++, 0) << "overlap";
  }
}

std::vector<RdmId> builtinRdms(const std::string& name) {
  Scene s = *builtinScene(name);
  return listRdms(buildWorld(s), s.bake);
}

TEST(Atlas, BuiltinScenesPackAtLeast95Percent) {
  for (const std::string name : {"chess", "island"}) {
    std::vector<RdmId> ids = builtinRdms(name);
    AtlasLayout layout = packCanonical(ids);
    expectValidLayout(layout, ids.size());
    EXPECT_GE(layout.occupancy(), 0.95) << name;
    EXPECT_EQ(layout.pages.size(), 1u);
  }
}

TEST(Atlas, PackingIsAPureFunctionOfTheRdmSet) {
  std::vector<RdmId> ids = builtinRdms("island");
  AtlasLayout a = packCanonical(ids);
  std::shuffle(ids.begin(), ids.end(), std::mt19937(4));
  AtlasLayout b = packCanonical(ids);
  EXPECT_EQ(indexToJson(a), indexToJson(b));
}

TEST(Atlas, MixedSizesPackDenselyAndSpillToFurtherPages) {
  std::vector<RdmId> ids;
  for (int i = 0; i < 800; ++i) ids.push_back({{i % 256, i / 256, 0}, 0, 256});
  for (int i = 0; i < 3000; ++i) ids.push_back({{i % 256, i / 256, 1}, 7, 2});
  AtlasLayout layout = packCanonical(ids);
  expectValidLayout(layout, ids.size());
  EXPECT_GE(layout.pages.size(), 2u);
  EXPECT_GE(layout.occupancy(), 0.9);
}

TEST(Atlas, IndexJsonRoundTripsAndTextMatchesThesisFormat) {
  std::vector<RdmId> ids = builtinRdms("chess");
  AtlasLayout layout = packCanonical(ids);
  layout.scene_version = 3;
  auto parsed = parseIndexJson(indexToJson(layout));
  ASSERT_TRUE(parsed.ok()) << parsed.error();
  EXPECT_EQ(indexToJson(*parsed), indexToJson(layout));
  std::string text = indexToText(layout);
  std::istringstream in(text);
  int count, w, h;
  in >> count >> w >> h;
  EXPECT_EQ(count, int(ids.size()));
  EXPECT_EQ(w, layout.pages[0].width);
  EXPECT_EQ(h, layout.pages[0].height);
  int i, j, k, level, x, y, rw, rh, lines = 0;
  while (in >> i >> j >> k >> level >> x >> y >> rw >> rh) {
    const AtlasEntry& e = layout.entries[lines++];
    EXPECT_EQ(glm::ivec3(i, j, k), e.id.slot);
    EXPECT_EQ(rw * 3, rh * 2);
    EXPECT_EQ(x, e.x);
  }
  EXPECT_EQ(lines, count);
  EXPECT_FALSE(parseIndexJson("{\"format\": \"nope\"}").ok());
}

TEST(Atlas, OutputsPlaceEveryTexelAndRefuseNonFinite) {
  std::string dir = testing::TempDir() + "/atlas_out_" + std::to_string(getpid());
  std::filesystem::remove_all(dir);
  std::vector<RdmData> rdms(2);
  rdms[0].id = {{0, 0, 0}, 7, 2};
  rdms[1].id = {{1, 0, 0}, 3, 4};
  for (RdmData& d : rdms) {
    d.image = Image(2 * d.id.size, 3 * d.id.size, 4);
    for (size_t p = 0; p < d.image.pixels.size(); ++p)
      d.image.pixels[p] = float(p % 97) + d.id.slot.x;
  }
  AtlasLayout layout = packCanonical({rdms[0].id, rdms[1].id});
  ASSERT_TRUE(writeAtlasOutputs(dir, layout, rdms).ok());
  auto atlas = readExr(dir + "/atlas.exr", kRgbzChannels);
  ASSERT_TRUE(atlas.ok()) << atlas.error();
  for (const AtlasEntry& e : layout.entries) {
    const RdmData& d = e.id == rdms[0].id ? rdms[0] : rdms[1];
    for (int y = 0; y < d.image.height; ++y)
      for (int x = 0; x < d.image.width; ++x)
        for (int c = 0; c < 4; ++c) ASSERT_EQ(atlas->at(e.x + x, e.y + y, c), d.image.at(x, y, c));
  }
  std::string bad_dir = testing::TempDir() + "/atlas_bad_" + std::to_string(getpid());
  std::filesystem::remove_all(bad_dir);
  rdms[1].image.at(1, 1, 2) = NAN;
  Status s = writeAtlasOutputs(bad_dir, layout, rdms);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("non-finite"), std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(bad_dir + "/atlas.exr"));
}

}  // namespace
}  // namespace rdm
