// MagicaVoxel import: a model built byte by byte, and malformed files refused cleanly.
#include <gtest/gtest.h>

#include <cstring>

#include "rdm/vox_import.h"
#include "rdm/world.h"

namespace rdm {
namespace {

void put32(std::string& s, uint32_t v) {
  s.append(reinterpret_cast<const char*>(&v), 4);
}

std::string chunk(const std::string& id, const std::string& content) {
  std::string s = id;
  put32(s, uint32_t(content.size()));
  put32(s, 0);
  return s + content;
}

// A 20 x 3 x 2 model (MagicaVoxel z up) with voxels at its corners.
std::string makeVox() {
  std::string size;
  for (uint32_t v : {20u, 3u, 2u}) put32(size, v);
  std::string xyzi;
  put32(xyzi, 3);
  for (auto v : {std::array<uint8_t, 4>{0, 0, 0, 5}, {19, 2, 1, 7}, {17, 0, 1, 5}})
    xyzi.append(reinterpret_cast<const char*>(v.data()), 4);
  std::string rgba(1024, '\0');
  rgba[4 * 4] = char(200);      // colour index 5 -> red 200
  rgba[6 * 4 + 1] = char(100);  // colour index 7 -> green 100
  std::string children = chunk("SIZE", size) + chunk("XYZI", xyzi) + chunk("RGBA", rgba);
  std::string main = "MAIN";
  put32(main, 0);
  put32(main, uint32_t(children.size()));
  std::string file = "VOX ";
  put32(file, 150);
  return file + main + children;
}

TEST(VoxImport, ModelBecomesBlocksWithYUp) {
  auto scene = importVox(makeVox());
  ASSERT_TRUE(scene.ok()) << scene.error();
  EXPECT_EQ(scene->size, (std::array<int, 3>{2, 1, 1}));  // 20 x 2 (up) x 3 voxels
  EXPECT_EQ(scene->palette.size(), 2u);
  EXPECT_EQ(scene->palette[0].color[0], 200);
  EXPECT_EQ(scene->palette[1].color[1], 100);
  VoxelWorld w = buildWorld(*scene);
  EXPECT_NE(w.voxelAt({0, 0, 2}), 0);   // vox (0,0,0) -> (0, 0, 3-1-0)
  EXPECT_NE(w.voxelAt({19, 1, 0}), 0);  // vox (19,2,1) -> (19, 1, 0)
  EXPECT_NE(w.voxelAt({17, 1, 2}), 0);
  EXPECT_EQ(w.voxelAt({1, 0, 2}), 0);
}

TEST(VoxImport, MalformedFilesAreRefusedWithOffsets) {
  std::string good = makeVox();
  EXPECT_FALSE(importVox("").ok());
  EXPECT_NE(importVox("PNG!....").error().find("magic"), std::string::npos);
  for (size_t cut : {10ul, 20ul, 30ul, 50ul, good.size() - 5}) {
    auto r = importVox(good.substr(0, cut));
    EXPECT_FALSE(r.ok()) << cut;
  }
  std::string bad = good;
  bad[bad.find("XYZI") + 12] = char(100);  // voxel count beyond the chunk
  auto r = importVox(bad);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().find("byte"), std::string::npos);
}

}  // namespace
}  // namespace rdm
