// Atlas deltas and per-RDM stores (rdm/atlas/atlas_delta.h, rdm/atlas/rdm_store.h): the wire layout
// round-trips bit for bit, anything malformed is refused naming the part, the selection
// follows origins and rects, and the store reads back exactly what was written.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>

#include "rdm/atlas/atlas_delta.h"
#include "rdm/atlas/rdm_store.h"
#include "rdm/bake/preview_pass.h"
#include "rdm/base/file_util.h"

namespace rdm {
namespace {

Image patternImage(int size, float seed) {
  Image img(2 * size, 3 * size, 4);
  for (size_t i = 0; i < img.pixels.size(); ++i) img.pixels[i] = seed + 0.001f * float(i);
  return img;
}

// The faces of `id` laid out as version 1's 2S x 3S rect at (x, y), face f stored when
// bit f of `mask` is set.
AtlasEntry rectEntry(const RdmId& id, int x, int y, FaceMask mask = kAllFaces) {
  AtlasEntry e{id, {}};
  for (int f = 0; f < 6; ++f) {
    if (mask >> f & 1u) e.faces[size_t(f)] = {0, x + id.size * (f % 2), y + id.size * (f / 2)};
  }
  return e;
}

// Face 3 of the rect is not stored: it must not travel and decodes as 0.
Image withoutFace3(Image img) {
  const int s = img.width / 2;
  for (int j = 0; j < s; ++j)
    for (int i = 0; i < s; ++i)
      for (int c = 0; c < 4; ++c) img.at(s + i, s + j, c) = 0.0f;
  return img;
}

AtlasDelta sampleDelta() {
  AtlasDelta d;
  d.job = "j0000000000000002", d.from = "j0000000000000001";
  d.pass = 0, d.passes = 2, d.final = false;
  d.settings = {1, 1, 7, 8};
  d.layout.pages = {{64, 64}};
  d.layout.entries = {rectEntry({{0, 0, 0}, 7, 8}, 0, 0),
                      rectEntry({{1, 0, 0}, 7, 4}, 16, 0, kAllFaces & ~0x08)};
  d.rects.push_back({d.layout.entries[1], withoutFace3(patternImage(4, 1.0f))});
  d.removed.push_back(rectEntry({{2, 0, 0}, 7, 4}, 24, 0));
  return d;
}

TEST(AtlasDelta, RoundTripsBitForBit) {
  const AtlasDelta d = sampleDelta();
  auto back = decodeAtlasDelta(encodeAtlasDelta(d));
  ASSERT_TRUE(back.ok()) << back.error();
  EXPECT_EQ(back->job, d.job);
  EXPECT_EQ(back->from, d.from);
  EXPECT_EQ(back->pass, 0);
  EXPECT_EQ(back->passes, 2);
  EXPECT_FALSE(back->final);
  EXPECT_EQ(back->settings, d.settings);
  ASSERT_EQ(back->layout.entries.size(), 2u);
  ASSERT_EQ(back->rects.size(), 1u);
  EXPECT_EQ(back->rects[0].entry.faces, d.rects[0].entry.faces);
  EXPECT_EQ(0, std::memcmp(back->rects[0].texels.pixels.data(), d.rects[0].texels.pixels.data(),
                           d.rects[0].texels.pixels.size() * sizeof(float)));
  ASSERT_EQ(back->removed.size(), 1u);
  EXPECT_EQ(back->removed[0].faces[0].x, 24);
  // Five 4 x 4 faces of RGBZ float32 after the header: the unstored face does not travel.
  uint32_t header = 0;
  const std::string bytes = encodeAtlasDelta(d);
  std::memcpy(&header, bytes.data() + 8, 4);
  EXPECT_EQ(bytes.size() - 12 - header, size_t(5 * 16 * 16));
}

TEST(AtlasDelta, RefusesMalformedMessages) {
  const std::string good = encodeAtlasDelta(sampleDelta());
  auto refused = [](const std::string& bytes, const std::string& part) {
    auto d = decodeAtlasDelta(bytes);
    ASSERT_FALSE(d.ok());
    EXPECT_EQ(d.status().code(), StatusCode::kInvalidInput);
    EXPECT_EQ(d.status().field(), part) << d.error();
  };
  refused("", "magic");
  refused("RDMDLT01" + good.substr(8), "magic");       // version 1 layout: whole 2S x 3S rects
  refused(good.substr(0, good.size() - 4), "texels");  // cut short
  refused(good + "x", "texels");                       // trailing bytes
  std::string huge = good;
  const uint32_t len = 0x7fffffffu;
  std::memcpy(huge.data() + 8, &len, 4);
  refused(huge, "header");
  AtlasDelta outside = sampleDelta();
  outside.rects[0].entry.faces[1].x = 62;  // S = 4 texels wide: past the 64-wide page
  refused(encodeAtlasDelta(outside), "rects[0]");
}

// A preview's RDMs travel at their own (smaller) size and decode expanded to the rect's.
TEST(AtlasDelta, SmallerTexelsTravelAsTheyAreAndDecodeExpanded) {
  AtlasDelta d = sampleDelta();
  d.rects[0].texels = withoutFace3(patternImage(2, 5.0f));  // the rect is size 4
  const std::string bytes = encodeAtlasDelta(d);
  EXPECT_LT(bytes.size(), encodeAtlasDelta(sampleDelta()).size());
  auto back = decodeAtlasDelta(bytes);
  ASSERT_TRUE(back.ok()) << back.error();
  EXPECT_EQ(back->rects[0].texels.pixels, expandRdmImage(d.rects[0].texels, 4).pixels);
  auto refused_size = [&](int texel_size) {
    std::string bad = bytes;
    const std::string from = "\"texel_size\":2",
                      to = "\"texel_size\":" + std::to_string(texel_size);
    bad.replace(bad.find(from), from.size(), to);
    uint32_t header = 0;
    std::memcpy(&header, bytes.data() + 8, 4);
    header = uint32_t(header + to.size() - from.size());
    std::memcpy(bad.data() + 8, &header, 4);
    auto r = decodeAtlasDelta(bad);
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.status().field(), "rects[0].texel_size") << r.error();
  };
  refused_size(0);
  refused_size(8);  // larger than the rect
}

TEST(AtlasDelta, SelectsNewMovedAndReoriginatedRdmsAndRemovedRects) {
  AtlasView old, now;
  old.layout.pages = now.layout.pages = {{64, 64}};
  const RdmId a{{0, 0, 0}, 7, 4}, b{{1, 0, 0}, 7, 4}, c{{2, 0, 0}, 7, 4}, d{{3, 0, 0}, 7, 4};
  old.layout.entries = {rectEntry(a, 0, 0), rectEntry(b, 8, 0), rectEntry(c, 16, 0)};
  now.layout.entries = {rectEntry(a, 0, 0), rectEntry(b, 8, 0), rectEntry(d, 24, 0)};
  old.origin = {{rdmKey(a), "j1"}, {rdmKey(b), "j1"}, {rdmKey(c), "j1"}};
  now.origin = {{rdmKey(a), "j1"}, {rdmKey(b), "j2"}, {rdmKey(d), "j2"}};
  const DeltaSelection sel = selectDelta(old, now);
  ASSERT_EQ(sel.rects.size(), 2u);  // b re-baked, d new; a unchanged
  EXPECT_EQ(sel.rects[0].id, b);
  EXPECT_EQ(sel.rects[1].id, d);
  ASSERT_EQ(sel.removed.size(), 1u);
  EXPECT_EQ(sel.removed[0].id, c);
  now.layout.entries[0].faces[2].x = 32;  // a face of a moved: rewritten, same origin
  EXPECT_EQ(selectDelta(old, now).rects.size(), 3u);
  now.layout.entries[0] = rectEntry(a, 0, 0, 0x1f);  // a's face 5 now skipped
  EXPECT_EQ(selectDelta(old, now).rects.size(), 3u);
  EXPECT_TRUE(samePages(old.layout, now.layout));
  now.layout.pages[0].height = 128;
  EXPECT_FALSE(samePages(old.layout, now.layout));
  EXPECT_TRUE(pagesGrow(old.layout, now.layout));  // taller: a client grows its texture
  EXPECT_FALSE(pagesGrow(now.layout, old.layout));
  now.layout.pages.push_back({32, 32});
  EXPECT_TRUE(pagesGrow(old.layout, now.layout));  // a page added
  old.layout.pages.push_back({64, 64});
  old.layout.pages.push_back({64, 64});
  EXPECT_FALSE(pagesGrow(old.layout, now.layout));  // a page dropped
}

TEST(RdmStore, ReadsBackEachRdmExactlyAndRefusesCorruptFiles) {
  const std::string dir = testing::TempDir() + "/rdm_store_" + std::to_string(getpid());
  std::filesystem::create_directories(dir);
  RdmData a, b;
  a.id = {{1, 2, 3}, 7, 2}, a.image = patternImage(2, 5.0f);
  b.id = {{1, 2, 3}, 3, 8}, b.image = patternImage(8, -2.0f);
  const std::string path = dir + "/rdms.store";
  const std::vector<RdmData> both{a, b};
  ASSERT_TRUE(writeRdmStore(path, MemoryRdmSource(both)).ok());
  auto reader = RdmStoreReader::open(path);
  ASSERT_TRUE(reader.ok()) << reader.error();
  for (const RdmData* d : {&a, &b}) {
    auto img = reader->read(rdmKey(d->id));
    ASSERT_TRUE(img.ok()) << img.error();
    EXPECT_EQ(img->pixels, d->image.pixels);
  }
  EXPECT_FALSE(reader->contains({9, 9, 9, 7}));
  EXPECT_EQ(reader->read({9, 9, 9, 7}).status().code(), StatusCode::kNotFound);
  std::string bytes = *readFileToString(path);
  // One flipped bit in b's texels (the last bytes of the file): b is refused naming its
  // slot and level, a still reads.
  std::string flipped = bytes;
  flipped[flipped.size() - 5] ^= 0x10;
  ASSERT_TRUE(writeFileAtomic(path, flipped).ok());
  auto damaged = RdmStoreReader::open(path);
  ASSERT_TRUE(damaged.ok()) << damaged.error();
  auto bad = damaged->read(rdmKey(b.id));
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.status().code(), StatusCode::kCorrupt);
  EXPECT_NE(bad.error().find("slot (1, 2, 3) level 3 fail their checksum"), std::string::npos)
      << bad.error();
  EXPECT_TRUE(damaged->read(rdmKey(a.id)).ok());
  ASSERT_TRUE(writeFileAtomic(path, bytes.substr(0, bytes.size() / 2)).ok());
  EXPECT_FALSE(RdmStoreReader::open(path).ok());  // an entry points past the end
  ASSERT_TRUE(writeFileAtomic(path, "not a store").ok());
  EXPECT_FALSE(RdmStoreReader::open(path).ok());
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace rdm
