// In-process incremental rebakes (rdm/atlas/incremental_baker.h), as the viewer's "bake" button
// runs them without a daemon: the first bake hands out every rect, an edit hands out a
// preview pass then a final pass over the re-baked RDMs only, and the final texels equal a
// full bake of the edited scene bit for bit.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>

#include "rdm/atlas/incremental_baker.h"
#include "rdm/bake/preview_pass.h"
#include "rdm/transport/rdm_shared_cpp.h"
#include "test_scenes.h"

namespace rdm {
namespace {

TEST(IncrementalBaker, EditRebakesDependentsInPassesBitIdenticalToAFullBake) {
  Scene scene = *builtinScene("chess");
  scene.bake.spp = 16, scene.bake.max_hemisphere = 8;
  IncrementalBaker baker;
  std::vector<AtlasDelta> first;
  ASSERT_TRUE(baker.bake(scene, {}, [&](AtlasDelta d) { first.push_back(std::move(d)); }).ok());
  ASSERT_EQ(first.size(), 1u);  // whole, one pass
  EXPECT_TRUE(first[0].final);
  EXPECT_EQ(first[0].rects.size(), first[0].layout.entries.size());

  const Scene edited = test::withoutPlacementAt(scene, {5, 1, 2});
  std::vector<AtlasDelta> passes;
  ASSERT_TRUE(baker.bake(edited, {}, [&](AtlasDelta d) { passes.push_back(std::move(d)); }).ok());
  ASSERT_EQ(passes.size(), 2u);
  EXPECT_FALSE(passes[0].final);
  EXPECT_EQ(passes[0].settings.spp, 1);
  EXPECT_TRUE(passes[1].final);
  EXPECT_EQ(passes[0].rects.size(), passes[1].rects.size());
  EXPECT_GT(passes[1].rects.size(), 0u);
  EXPECT_LT(passes[1].rects.size(), passes[1].layout.entries.size());

  const VoxelWorld world = buildWorld(edited);
  BakeOptions options;
  options.threads = 2;
  std::map<RdmKey, std::vector<float>> full;
  for (const RdmData& d : bakeScene(world, edited.bake, options).rdms)
    full[rdmKey(d.id)] = d.image.pixels;
  int differ = 0;
  for (const DeltaRect& r : passes[1].rects)
    differ += full.at(rdmKey(r.entry.id)) != r.texels.pixels;
  EXPECT_EQ(differ, 0);
  // The preview is a bake at its own settings (half the sizes), each RDM expanded.
  std::vector<RdmId> ids;
  for (const DeltaRect& r : passes[0].rects) ids.push_back(r.entry.id);
  const BakeSettings preview = passes[0].settings;
  EXPECT_EQ(preview, progressivePasses(edited.bake).front());
  int preview_differ = 0;
  for (const RdmData& d : bakeRdms(world, preview, atPassSizes(ids, preview), options).rdms) {
    const int size = shared::hemisphereSize(d.id.level, edited.bake.max_hemisphere);
    for (const DeltaRect& r : passes[0].rects)
      if (rdmKey(r.entry.id) == rdmKey(d.id))
        preview_differ += expandRdmImage(d.image, size).pixels != r.texels.pixels;
  }
  EXPECT_EQ(preview_differ, 0);
}

TEST(IncrementalBaker, CancelledRebakeRestoresTheLastAtlasAndKeepsItsState) {
  Scene scene = *builtinScene("chess");
  scene.bake.spp = 16, scene.bake.max_hemisphere = 8;
  IncrementalBaker baker;
  std::vector<AtlasDelta> first;
  ASSERT_TRUE(baker.bake(scene, {}, [&](AtlasDelta d) { first.push_back(std::move(d)); }).ok());
  Scene edited = scene;
  edited.placements.pop_back();
  std::atomic<bool> cancel{false};
  IncrementalBakeOptions options;
  options.cancel = &cancel;
  std::vector<AtlasDelta> seen;
  const Status s = baker.bake(edited, options, [&](AtlasDelta d) {
    seen.push_back(std::move(d));
    cancel = true;  // right after the preview is out
  });
  EXPECT_EQ(s.code(), StatusCode::kCancelled);
  ASSERT_EQ(seen.size(), 2u);  // the preview, then the restore
  EXPECT_TRUE(seen[1].final);
  std::map<RdmKey, std::vector<float>> before;
  for (const DeltaRect& r : first[0].rects) before[rdmKey(r.entry.id)] = r.texels.pixels;
  for (const DeltaRect& r : seen[1].rects)
    EXPECT_EQ(before.at(rdmKey(r.entry.id)), r.texels.pixels);
}

}  // namespace
}  // namespace rdm
