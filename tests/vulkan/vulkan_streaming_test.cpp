// A Vulkan bake that streams its RDMs out (VulkanBakeOptions::on_rdm_done), as `rdm bake`
// does into its spill file: every RDM once, with the bits and slot sets of a bake that kept
// them all, while the bake holds only the RDMs in flight. Both estimators.
#include <gtest/gtest.h>

#include <map>
#include <vector>

#include "bake_identity.h"
#include "rdm/bake/bake.h"
#include "rdm/vulkan/vulkan_bake.h"
#include "test_scenes.h"
#include "vulkan_bake_support.h"

namespace rdm {
namespace {

void expectStreamedAsKept(Estimator estimator) {
  Scene s = *builtinScene("chess");
  s.bake = {2, 3, 1, 8, estimator};
  const VoxelWorld world = buildWorld(s);
  const std::vector<RdmId> ids = listRdms(world, s.bake);
  VulkanBakeOptions kept_options;
  kept_options.record_slot_sets = true;
  auto kept = bakeRdmsVulkan(world, s.bake, ids, kept_options);
  ASSERT_TRUE(kept) << kept.error();

  VulkanBakeOptions streaming = kept_options;
  streaming.max_batch_paths = 256;     // many batches, so few RDMs are in flight at once
  std::map<size_t, RdmData> streamed;  // by position in `ids`
  streaming.on_rdm_done = [&](const RdmData& d) {
    const size_t r = size_t(std::find(ids.begin(), ids.end(), d.id) - ids.begin());
    EXPECT_EQ(streamed.count(r), 0u) << "RDM " << r << " handed out twice";
    streamed[r] = d;
  };
  auto result = bakeRdmsVulkan(world, s.bake, ids, streaming);
  ASSERT_TRUE(result) << result.error();
  ASSERT_EQ(streamed.size(), ids.size());
  BakeResult from_stream;
  for (auto& [r, d] : streamed) from_stream.rdms.push_back(std::move(d));
  EXPECT_TRUE(test::bitIdentical(*kept, from_stream));
  for (size_t r = 0; r < ids.size(); ++r) {
    EXPECT_EQ(from_stream.rdms[r].full_set, kept->rdms[r].full_set) << r;
    EXPECT_EQ(from_stream.rdms[r].first_set, kept->rdms[r].first_set) << r;
    EXPECT_TRUE(result->rdms[r].image.pixels.empty()) << "RDM " << r << " kept its texels";
    EXPECT_TRUE(result->rdms[r].full_set.empty()) << "RDM " << r << " kept its sets";
  }
  // The report's statistics are those of the kept bake; few RDMs were held at once.
  EXPECT_EQ(result->report.mean_relative_error, kept->report.mean_relative_error);
  EXPECT_EQ(kept->report.peak_rdms_held, int(ids.size()));
  EXPECT_LT(result->report.peak_rdms_held, int(ids.size()) / 4);
}

TEST(VulkanStreaming, NaiveRdmsLeaveAsTheyFinishWithTheKeptBits) {
  RDM_REQUIRE_VULKAN();
  expectStreamedAsKept(Estimator::kNaive);
}

TEST(VulkanStreaming, PrefilteredRdmsLeaveAsTheyFinishWithTheKeptBits) {
  RDM_REQUIRE_VULKAN();
  expectStreamedAsKept(Estimator::kPrefiltered);
}

}  // namespace
}  // namespace rdm
