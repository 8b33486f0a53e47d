// Bounded-memory bakes (docs/spec.md section 4): RDMs streamed to a spill file as they finish,
// the atlas and noise written page by page from it, and pages no larger than kPackedPageSize.
// Every comparison here is exact: streaming changes where texels wait, never their bits.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <unistd.h>

#include <filesystem>
#include <mutex>

#include "bake_identity.h"
#include "rdm/atlas/atlas.h"
#include "rdm/bake/bake.h"
#include "rdm/bake/rdm_source.h"
#include "rdm/base/file_util.h"
#include "test_scenes.h"

namespace rdm {
namespace {

std::string freshDir(const std::string& name) {
  const std::string dir =
      testing::TempDir() + "/rdm_source_" + std::to_string(getpid()) + "_" + name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

// test::mixedScene (diffuse, mirror and rough RDMs of several sizes), sun-lit, S <= 16.
Scene mixedScene() {
  Scene s = test::mixedScene();
  s.sun = Sun{{0.4, 1.0, 0.3}, {3.0, 3.0, 3.0}, 0.5};
  s.bake.max_hemisphere = 16;
  return s;
}

BakeResult bakeWhole(const VoxelWorld& world, const BakeSettings& settings) {
  BakeOptions options;
  options.threads = 2;
  return bakeScene(world, settings, options);
}

struct StreamedBake {
  BakeResult result;
  std::vector<RdmData> streamed;  // as on_rdm_done saw them, in canonical order
};

StreamedBake bakeStreamed(const VoxelWorld& world, const BakeSettings& settings, int threads) {
  StreamedBake out;
  std::mutex mutex;
  BakeOptions options;
  options.threads = threads;
  options.on_rdm_done = [&](const RdmData& rdm) {
    std::lock_guard lock(mutex);
    out.streamed.push_back(rdm);
  };
  out.result = bakeScene(world, settings, options);
  std::sort(out.streamed.begin(), out.streamed.end(),
            [](const RdmData& a, const RdmData& b) { return canonicalLess(a.id, b.id); });
  return out;
}

TEST(RdmSource, StreamedBakeHandsOverEveryRdmBitIdenticalAndFreesIt) {
  const Scene s = mixedScene();
  const VoxelWorld world = buildWorld(s);
  const BakeResult whole = bakeWhole(world, s.bake);
  StreamedBake streamed = bakeStreamed(world, s.bake, 2);
  BakeResult as_whole;
  as_whole.rdms = streamed.streamed;
  EXPECT_TRUE(test::bitIdentical(whole, as_whole));
  for (const RdmData& d : streamed.result.rdms) EXPECT_TRUE(d.image.pixels.empty());
  // The report's figures are summed per RDM in canonical order in both bakes: equal exactly.
  EXPECT_EQ(streamed.result.report.texels, whole.report.texels);
  EXPECT_EQ(streamed.result.report.mean_relative_error, whole.report.mean_relative_error);
  EXPECT_EQ(streamed.result.report.max_relative_error, whole.report.max_relative_error);
  EXPECT_EQ(whole.report.peak_rdms_held, int(whole.rdms.size()));
}

// Units run slot by slot, so at most `threads` slots' RDMs (one per level present, at most 8)
// are held at once, however large the world.
TEST(RdmSource, StreamedBakeHoldsOnlyTheSlotsInFlight) {
  Scene s = test::randomVoxelScene(6, 2, 6, 0.3, 11);
  s.bake = {1, 1, 1, 4};
  const VoxelWorld world = buildWorld(s);
  const int threads = 2;
  StreamedBake streamed = bakeStreamed(world, s.bake, threads);
  const int rdms = int(streamed.result.rdms.size());
  ASSERT_GT(rdms, 40);
  EXPECT_EQ(int(streamed.streamed.size()), rdms);
  EXPECT_GE(streamed.result.report.peak_rdms_held, 1);
  EXPECT_LE(streamed.result.report.peak_rdms_held, threads * 8);
  EXPECT_LT(streamed.result.report.peak_rdms_held, rdms / 4);
}

TEST(RdmSource, SpillReadsBackWhatWasAppended) {
  const Scene s = mixedScene();
  const VoxelWorld world = buildWorld(s);
  StreamedBake streamed = bakeStreamed(world, s.bake, 1);
  const std::string dir = freshDir("spill");
  auto spill = RdmSpill::create(dir);
  ASSERT_TRUE(spill.ok()) << spill.error();
  for (auto it = streamed.streamed.rbegin(); it != streamed.streamed.rend(); ++it)
    (*spill)->append(*it);
  ASSERT_TRUE((*spill)->status().ok());
  EXPECT_TRUE(std::filesystem::is_empty(dir));  // the file has no name
  const std::vector<RdmId> ids = (*spill)->ids();
  ASSERT_EQ(ids.size(), streamed.streamed.size());
  for (size_t i = 0; i < ids.size(); ++i) {
    const RdmData& expected = streamed.streamed[ids.size() - 1 - i];
    ASSERT_TRUE((*spill)
                    ->visit(i,
                            [&](const RdmData& back) {
                              EXPECT_EQ(back.id, expected.id);
                              EXPECT_TRUE(
                                  test::sameBytes(back.image.pixels, expected.image.pixels));
                              EXPECT_TRUE(test::sameBytes(back.stderr_rgb, expected.stderr_rgb));
                              EXPECT_EQ(back.skipped, expected.skipped);
                              EXPECT_EQ(back.max_samples, expected.max_samples);
                            })
                    .ok());
  }
  EXPECT_EQ((*spill)->bytes(), [&] {
    size_t bytes = 0;
    for (const RdmData& d : streamed.streamed) bytes += 28 * size_t(d.image.width) * d.image.height;
    return bytes;
  }());
}

// The spill file has no name: find it among this process's descriptors (/proc/self/fd links
// to "<dir>/#<inode> (deleted)" or "<dir>/.rdm-spill-XXXXXX (deleted)").
int openSpillFile(const std::string& dir) {
  const std::string canonical = std::filesystem::canonical(dir).string() + "/";
  for (const auto& entry : std::filesystem::directory_iterator("/proc/self/fd")) {
    std::error_code ec;
    const std::string target = std::filesystem::read_symlink(entry.path(), ec).string();
    if (!ec && target.rfind(canonical, 0) == 0)
      return ::open(entry.path().c_str(), O_RDWR | O_CLOEXEC);
  }
  return -1;
}

TEST(RdmSource, SpillRecordWithAFlippedBitFailsAloneAsCorrupt) {
  const Scene s = mixedScene();
  const VoxelWorld world = buildWorld(s);
  StreamedBake streamed = bakeStreamed(world, s.bake, 1);
  ASSERT_GE(streamed.streamed.size(), 3u);
  const std::string dir = freshDir("spill_flip");
  auto spill = RdmSpill::create(dir);
  ASSERT_TRUE(spill.ok()) << spill.error();
  for (const RdmData& d : streamed.streamed) (*spill)->append(d);
  const int fd = openSpillFile(dir);
  ASSERT_GE(fd, 0);
  // A bit of record 1's standard error (its last bytes), then one of record 2's texels.
  const uint64_t first = RdmSpill::fileBytes(streamed.streamed[0].id);
  const uint64_t second = RdmSpill::fileBytes(streamed.streamed[1].id);
  for (const uint64_t at : {first + second - 3, first + second + 5}) {
    char byte = 0;
    ASSERT_EQ(::pread(fd, &byte, 1, off_t(at)), 1);
    byte = char(byte ^ 0x10);
    ASSERT_EQ(::pwrite(fd, &byte, 1, off_t(at)), 1);
  }
  ::close(fd);
  bool used = false;
  EXPECT_TRUE((*spill)->visit(0, [&](const RdmData&) { used = true; }).ok());
  EXPECT_TRUE(used);
  for (size_t i : {size_t(1), size_t(2)}) {
    used = false;
    const Status read = (*spill)->visit(i, [&](const RdmData&) { used = true; });
    ASSERT_FALSE(read.ok()) << i;
    EXPECT_EQ(read.code(), StatusCode::kCorrupt);
    EXPECT_NE(read.message().find("checksum"), std::string::npos) << read.message();
    EXPECT_FALSE(used) << "a damaged record is never handed out";
  }
  for (size_t i = 3; i < streamed.streamed.size(); ++i)
    EXPECT_TRUE((*spill)->visit(i, [](const RdmData&) {}).ok()) << i;
}

TEST(RdmSource, AtlasFromTheSpillEqualsTheAtlasFromMemoryByteForByte) {
  const Scene s = mixedScene();
  const VoxelWorld world = buildWorld(s);
  const BakeResult whole = bakeWhole(world, s.bake);
  const std::string dir = freshDir("atlas");
  auto spill = RdmSpill::create(dir);
  ASSERT_TRUE(spill.ok()) << spill.error();
  for (const RdmData& d : whole.rdms) (*spill)->append(d);
  std::vector<RdmId> ids;
  for (const RdmData& d : whole.rdms) ids.push_back(d.id);
  for (RadianceFormat format : {RadianceFormat::kFloat32, RadianceFormat::kHalf}) {
    AtlasLayout layout = packCanonical(ids, storedFacesOf(world));
    layout.radiance = format;
    const std::string a = dir + "/memory", b = dir + "/spill";
    ASSERT_TRUE(writeAtlasOutputs(a, layout, whole.rdms).ok());
    ASSERT_TRUE(writeAtlasOutputs(b, layout, **spill).ok());
    for (const char* file : {"atlas.exr", "index.json", "index.txt"}) {
      auto x = readFileToString(a + "/" + file), y = readFileToString(b + "/" + file);
      ASSERT_TRUE(x.ok() && y.ok());
      EXPECT_TRUE(*x == *y) << file << " differs (" << radianceFormatName(format) << ")";
    }
  }
}

// A world of 3000 RDMs of S = 128 (49 M texels, 4.6 x 4096^2) packs into pages of at most
// 4096 x 4096, each RDM's tiles inside its pages.
TEST(RdmSource, PackedPagesNeverExceedThePackedPageSize) {
  std::vector<RdmId> ids;
  for (int i = 0; i < 3000; ++i) ids.push_back({{i % 50, 0, i / 50}, 7, 128});
  const AtlasLayout layout = packCanonical(ids, allFaces);
  EXPECT_GE(layout.pages.size(), 5u);
  for (const AtlasPage& p : layout.pages) {
    EXPECT_LE(p.width, kPackedPageSize);
    EXPECT_LE(p.height, kPackedPageSize);
  }
  for (const AtlasEntry& e : layout.entries) EXPECT_TRUE(tilesFit(e, layout.pages));
  EXPECT_GT(layout.occupancy(), 0.9);
}

}  // namespace
}  // namespace rdm
