// Slot-set recording of the Vulkan kernel (docs/spec.md section 8,
// VulkanBakeOptions::record_slot_sets): no image bit changes, the sets survive suspension and
// batch cuts, they match the CPU's, and they keep the exact-rebake contract. And a VulkanBaker
// kept across bakes gives a fresh bake's bits and sets.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <iterator>
#include <string>
#include <vector>

#include "bake_identity.h"
#include "rdm/bake/bake.h"
#include "rdm/transport/rdm_shared_cpp.h"
#include "rdm/vulkan/vulkan_bake.h"
#include "test_scenes.h"
#include "vulkan_bake_support.h"

namespace rdm {
namespace {

using glm::ivec3;
using test::bakeVulkan;
using test::bitIdentical;
using test::hardScene;
using test::naive;

bool sortedUnique(const std::vector<uint32_t>& v) {
  return std::adjacent_find(v.begin(), v.end(), [](uint32_t a, uint32_t b) { return a >= b; }) ==
         v.end();
}

bool sameSets(const BakeResult& a, const BakeResult& b) {
  if (a.rdms.size() != b.rdms.size()) return false;
  for (size_t r = 0; r < a.rdms.size(); ++r) {
    const RdmData& x = a.rdms[r];
    const RdmData& y = b.rdms[r];
    if (x.full_set != y.full_set || x.first_set != y.first_set ||
        x.smooth_vertex != y.smooth_vertex)
      return false;
  }
  return true;
}

// Chess with a lamp on the board's edge and a low sun (its shadow rays cross several slots):
// sun and emitter shadow rays, mirrors (gold) and glossy tiles, at settings small enough for
// a few lavapipe bakes per test.
Scene chessWithLamp() {
  Scene s = *builtinScene("chess");
  s.palette.push_back({{255, 220, 160}, 7, 0, 3});
  const int lamp = int(s.palette.size());
  s.blocks["lamp"] = test::blockFrom([&](int x, int y, int z) {
    return x >= 6 && x < 10 && z >= 6 && z < 10 && y < 5 ? lamp : 0;
  });
  s.placements.push_back({{0, 1, 4}, "lamp", 0});
  s.sun->direction = glm::dvec3(-0.3, 0.3, 1.0);
  s.bake.spp = 4;
  s.bake.max_bounces = 3;
  s.bake.max_hemisphere = 8;
  s.bake.estimator = Estimator::kNaive;
  return s;
}

TEST(VulkanSlotSets, RecordingChangesNoBitAndSurvivesSuspension) {
  RDM_REQUIRE_VULKAN();
  const test::HardCase hard;
  VulkanBakeOptions rec;
  rec.record_slot_sets = true;
  const BakeResult plain = hard.bake();
  const BakeResult recorded = hard.bake(rec);
  EXPECT_TRUE(bitIdentical(plain, recorded)) << "recording changed the image or its errors";
  EXPECT_EQ(plain.report.rays, recorded.report.rays);
  for (const RdmData& d : plain.rdms) EXPECT_TRUE(d.full_set.empty() && !d.smooth_vertex);
  // Paths suspended and resumed many times, RDMs split across batches: the same sets.
  rec.max_batch_paths = 96;
  rec.loop_budget = 400;
  VulkanBakeInfo info;
  rec.info = &info;
  const BakeResult split = hard.bake(rec);
  EXPECT_GT(info.max_dispatches_per_batch, 1u);
  EXPECT_TRUE(bitIdentical(plain, split));
  EXPECT_TRUE(sameSets(recorded, split)) << "suspension or batching changed the slot sets";
}

// Sorted, unique, first within full, and close to the CPU's sets on the same scene: both
// backends draw the same random numbers, so they trace nearly the same rays.
TEST(VulkanSlotSets, SetsAreWellFormedAndMatchTheCpuClosely) {
  RDM_REQUIRE_VULKAN();
  Scene s = chessWithLamp();
  VoxelWorld world = buildWorld(s);
  ASSERT_FALSE(world.emitters.empty());
  std::vector<RdmId> ids = listRdms(world, s.bake);
  VulkanBakeOptions rec;
  rec.record_slot_sets = true;
  const BakeResult vk = bakeVulkan(world, s.bake, ids, rec);
  BakeOptions cpu_options;
  cpu_options.threads = 2;
  cpu_options.record_slot_sets = true;
  const BakeResult cpu = bakeRdms(world, s.bake, ids, cpu_options);
  ASSERT_EQ(vk.rdms.size(), cpu.rdms.size());
  size_t cpu_entries = 0, missing = 0, extra = 0, first_missing = 0, smooth_differ = 0;
  for (size_t r = 0; r < vk.rdms.size(); ++r) {
    const RdmData& v = vk.rdms[r];
    const RdmData& c = cpu.rdms[r];
    const ivec3 slot = v.id.slot;
    const std::string where = "slot (" + std::to_string(slot.x) + "," + std::to_string(slot.y) +
                              "," + std::to_string(slot.z) + ") level " +
                              std::to_string(v.id.level);
    EXPECT_TRUE(sortedUnique(v.full_set) && sortedUnique(v.first_set)) << where;
    EXPECT_TRUE(
        std::includes(v.full_set.begin(), v.full_set.end(), v.first_set.begin(), v.first_set.end()))
        << where;
    // Must hold: every first segment and central ray of a baked face starts in the
    // neighbour slot across it (section 5's boundary rule), when that slot is in the grid.
    for (int f = 0; f < 6; ++f) {
      const ivec3 n = slot + shared::faceNormal(f);
      if (v.skipped[size_t(f)] || !world.slotInGrid(n)) continue;
      EXPECT_TRUE(
          std::binary_search(v.first_set.begin(), v.first_set.end(), uint32_t(world.slotLinear(n))))
          << where << " face " << f;
    }
    std::vector<uint32_t> diff;
    std::set_difference(c.full_set.begin(), c.full_set.end(), v.full_set.begin(), v.full_set.end(),
                        std::back_inserter(diff));
    missing += diff.size();
    diff.clear();
    std::set_difference(v.full_set.begin(), v.full_set.end(), c.full_set.begin(), c.full_set.end(),
                        std::back_inserter(diff));
    extra += diff.size();
    diff.clear();
    std::set_difference(c.first_set.begin(), c.first_set.end(), v.first_set.begin(),
                        v.first_set.end(), std::back_inserter(diff));
    first_missing += diff.size();
    cpu_entries += c.full_set.size();
    smooth_differ += v.smooth_vertex != c.smooth_vertex ? 1 : 0;
  }
  std::printf(
      "[ sets ] %zu RDMs, %zu CPU full-set entries; Vulkan lacks %zu and adds %zu of them "
      "(first sets: lacks %zu); smooth_vertex differs on %zu RDMs\n",
      vk.rdms.size(), cpu_entries, missing, extra, first_missing, smooth_differ);
  // The rays differ only where float rounding splits a path (ray counts agree within 1%), and
  // a split path's slots are mostly also met by the texel's other paths: allow 1% of the
  // entries either way. First segments start from the same origins and directions.
  EXPECT_LE(double(missing), 0.01 * double(cpu_entries));
  EXPECT_LE(double(extra), 0.01 * double(cpu_entries));
  EXPECT_LE(double(first_missing), 0.01 * double(cpu_entries));
  EXPECT_EQ(smooth_differ, 0u);
}

// One VulkanBaker for several bakes and kernel variants: the same bits as a fresh
// bakeRdmsVulkan each time.
TEST(VulkanBaker, KeepsItsPipelinesAcrossBakesWithTheSameBits) {
  RDM_REQUIRE_VULKAN();
  auto baker = VulkanBaker::create("");
  ASSERT_TRUE(baker) << baker.error();
  EXPECT_FALSE((*baker)->device().name.empty());
  Scene s = hardScene();
  s.bake = {4, 4, 2, 4};
  Scene plain = s;
  plain.sun.reset();
  const VoxelWorld world = buildWorld(s), plain_world = buildWorld(plain);
  const BakeSettings settings = naive(s.bake);
  const std::vector<RdmId> ids = listRdms(world, settings);
  VulkanBakeOptions rec;
  rec.record_slot_sets = true;
  std::vector<BakeResult> fresh;
  for (const VoxelWorld* w : {&world, &plain_world}) {
    for (const VulkanBakeOptions& o : {VulkanBakeOptions{}, rec})
      fresh.push_back(bakeVulkan(*w, settings, ids, o));
  }
  for (int round = 0; round < 2; ++round) {
    size_t n = 0;
    for (const VoxelWorld* w : {&world, &plain_world}) {
      for (const VulkanBakeOptions& o : {VulkanBakeOptions{}, rec}) {
        auto kept = (*baker)->bake(*w, settings, ids, o);
        ASSERT_TRUE(kept) << kept.error();
        EXPECT_TRUE(bitIdentical(*kept, fresh[n])) << "round " << round << ", bake " << n;
        EXPECT_TRUE(sameSets(*kept, fresh[n])) << "round " << round << ", bake " << n;
        ++n;
      }
    }
  }
}

// A grid of 2^20 slots needs 256 KiB of bitsets per RDM: the 64 MiB cap cuts the batch after
// 255 RDMs, at an RDM boundary, and the sets and bits stay those of other splits.
TEST(VulkanSlotSets, LargeGridsCutBatchesAtRdmBoundaries) {
  RDM_REQUIRE_VULKAN();
  Scene s = test::uniformSkyScene(256, 16, 256);
  s.blocks["post"] = test::blockFrom([](int x, int, int z) { return x < 4 && z < 4 ? 1 : 0; });
  for (int k = 0; k < 15; ++k)
    for (int i = 0; i < 20; ++i) s.placements.push_back({{6 * i + 3, 2, 6 * k + 5}, "post", 0});
  s.bake = {1, 2, 9, 2};
  VoxelWorld world = buildWorld(s);
  std::vector<RdmId> ids = listRdms(world, s.bake);
  ASSERT_EQ(ids.size(), 300u);
  VulkanBakeOptions rec;
  rec.record_slot_sets = true;
  VulkanBakeInfo info;
  rec.info = &info;
  const BakeResult one = bakeVulkan(world, s.bake, ids, rec);
  EXPECT_EQ(info.batches, 2u) << "300 RDMs at 255 per batch";
  rec.max_batch_paths = 100;  // batches of 100 texel jobs: RDMs (24 jobs) split across them
  const BakeResult split = bakeVulkan(world, s.bake, ids, rec);
  EXPECT_EQ(info.batches, 72u);
  EXPECT_TRUE(bitIdentical(one, split));
  EXPECT_TRUE(sameSets(one, split));
  EXPECT_TRUE(bitIdentical(one, bakeVulkan(world, s.bake, ids)));
  // A post's six neighbours are empty and in the grid: first segments start in each of them.
  for (const RdmData& d : one.rdms) EXPECT_GE(d.first_set.size(), 6u);
}

// The contract: after changing the voxels of one slot X, every RDM whose Vulkan full set
// does not hold X (and that is not X's or a 6-neighbour's) bakes to the same bits on Vulkan.
TEST(VulkanSlotSets, RdmsWhoseFullSetMissesAChangedSlotKeepTheirBits) {
  RDM_REQUIRE_VULKAN();
  Scene a = chessWithLamp();
  // X: an empty slot in the middle of the board gets a solid block, so every ray of A that
  // crossed X (path segment, sun or emitter shadow ray) is stopped in B.
  const ivec3 x_slot(3, 1, 4);
  Scene b = a;
  b.blocks["pillar"] = test::blockFrom([](int, int, int) { return 3; });
  b.placements.push_back({{x_slot.x, x_slot.y, x_slot.z}, "pillar", 0});
  VoxelWorld wa = buildWorld(a), wb = buildWorld(b);
  ASSERT_LT(wa.blockAt(x_slot), 0) << "X must be empty in A";
  ASSERT_EQ(wa.emitters.emitters.size(), wb.emitters.emitters.size());
  for (size_t e = 0; e < wa.emitters.emitters.size(); ++e) {
    ASSERT_EQ(wa.emitters.emitters[e].voxel, wb.emitters.emitters[e].voxel);
    ASSERT_EQ(wa.emitters.emitters[e].face, wb.emitters.emitters[e].face);
  }
  VulkanBakeOptions rec;
  rec.record_slot_sets = true;
  const BakeResult ra = bakeVulkan(wa, a.bake, listRdms(wa, a.bake), rec);
  const BakeResult rb = bakeVulkan(wb, b.bake, listRdms(wb, b.bake));
  const uint32_t x = uint32_t(wa.slotLinear(x_slot));
  int kept = 0, dependents = 0, changed = 0;
  for (const RdmData& da : ra.rdms) {
    const ivec3 d = glm::abs(da.id.slot - x_slot);
    if (d.x + d.y + d.z <= 1) continue;  // X and its 6-neighbours are always re-baked
    auto it = std::find_if(rb.rdms.begin(), rb.rdms.end(),
                           [&](const RdmData& r) { return r.id == da.id; });
    ASSERT_NE(it, rb.rdms.end());
    const bool same = test::sameBytes(da.image.pixels, it->image.pixels) &&
                      test::sameBytes(da.stderr_rgb, it->stderr_rgb);
    if (std::binary_search(da.full_set.begin(), da.full_set.end(), x)) {
      ++dependents, changed += same ? 0 : 1;
      continue;
    }
    ++kept;
    EXPECT_TRUE(same) << "slot (" << da.id.slot.x << "," << da.id.slot.y << "," << da.id.slot.z
                      << ") level " << da.id.level
                      << " changed, but its full set does not hold the changed slot";
  }
  std::printf("[ contract ] %d RDMs outside X's reach kept, %d dependents (%d changed)\n", kept,
              dependents, changed);
  // Not vacuous: both kinds exist, and the edit changes RDMs beyond X's neighbours.
  EXPECT_GT(kept, 10);
  EXPECT_GT(changed, 0);
}

}  // namespace
}  // namespace rdm
