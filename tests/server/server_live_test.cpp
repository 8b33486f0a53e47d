// Progressive incremental jobs against a real `rdm serve` (docs/api.md, "Progressive
// incremental jobs"): each pass is published and fetched as one delta.bin request; the
// preview pass equals an in-process bake at the preview settings and the final pass of an
// exact job equals a full bake of the new scene, bit for bit; deltas that do not chain and
// stale PATCHes are refused with 409.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <map>

#include "rdm/atlas/atlas_delta.h"
#include "rdm/bake/bake.h"
#include "rdm/bake/preview_pass.h"
#include "rdm/bake/rebake_selection.h"
#include "rdm/image/exr_io.h"
#include "rdm/scene/scene_patch.h"
#include "rdm/service/client.h"
#include "server_process.h"

namespace rdm {
namespace {

using nlohmann::json;

struct Fixture {
  std::string dir;
  std::unique_ptr<test::ServerProcess> server;
  std::unique_ptr<BakeClient> client;
  Scene scene;
  std::string scene_id, base_job;
};

// Chess small enough for a test, with enough samples that the preview pass (spp / 16) and
// the final pass are far apart in time.
void start(Fixture& f, const std::string& name) {
  f.dir = testing::TempDir() + "/server_live_" + std::to_string(getpid()) + "_" + name;
  std::filesystem::remove_all(f.dir);
  std::filesystem::create_directories(f.dir);
  f.server =
      std::make_unique<test::ServerProcess>(f.dir, std::vector<std::string>{"--threads", "2"});
  ASSERT_GT(f.server->port(), 0);
  f.client = test::connectClient(*f.server);
  f.scene = *builtinScene("chess");
  f.scene.bake.spp = 64, f.scene.bake.max_hemisphere = 16;
  f.scene.face_light_spp = 0;  // the RDM passes are what these tests follow
  auto up = f.client->uploadScene(sceneToJson(f.scene));
  ASSERT_TRUE(up.ok()) << up.error();
  f.scene_id = (*up)["id"];
  auto job = f.client->submitBake(f.scene_id, json::object());
  ASSERT_TRUE(job.ok()) << job.error();
  f.base_job = (*job)["id"];
  auto done = f.client->jobProgress(f.base_job, 30.0);
  for (int i = 0; i < 10 && done.ok() && !done->terminal(); ++i)
    done = f.client->jobProgress(f.base_job, 30.0);
  ASSERT_TRUE(done.ok() && done->succeeded()) << (done.ok() ? done->state : done.error());
}

Scene withoutPawn(const Scene& s) {
  Scene out = s;
  auto& p = out.placements;
  p.erase(std::remove_if(p.begin(), p.end(),
                         [](const Placement& q) {
                           return q.at == std::array<int, 3>{5, 1, 2};
                         }),
          p.end());
  return out;
}

// A bake of `ids` at a pass's settings (its sizes), each RDM expanded to its size in `ids`.
std::map<RdmKey, Image> bakeIds(const Scene& scene, const BakeSettings& settings,
                                const std::vector<RdmId>& ids) {
  const VoxelWorld world = buildWorld(scene);
  BakeOptions options;
  options.threads = 2;
  std::map<RdmKey, int> sizes;
  for (const RdmId& id : ids) sizes[rdmKey(id)] = id.size;
  std::map<RdmKey, Image> out;
  for (RdmData& d : bakeRdms(world, settings, atPassSizes(ids, settings), options).rdms)
    out[rdmKey(d.id)] = expandRdmImage(d.image, sizes.at(rdmKey(d.id)));
  return out;
}

int mismatchedRects(const AtlasDelta& delta, const std::map<RdmKey, Image>& reference) {
  int bad = 0;
  for (const DeltaRect& r : delta.rects) {
    auto it = reference.find(rdmKey(r.entry.id));
    bad += it == reference.end() || it->second.pixels != r.texels.pixels;
  }
  return bad;
}

TEST(ServerLive, EachPassIsOneDeltaEqualToABakeAtItsSettings) {
  Fixture f;
  start(f, "passes");
  const Scene edited = withoutPawn(f.scene);
  auto patched = f.client->patchScene(f.scene_id, makeScenePatch(f.scene, edited, 1));
  ASSERT_TRUE(patched.ok()) << patched.error();
  auto job = f.client->submitBake(f.scene_id, {{"mode", "exact"}});
  ASSERT_TRUE(job.ok()) << job.error();
  const std::string id = (*job)["id"];

  auto after_preview = f.client->jobProgress(id, 30.0, 1);  // long poll for the preview
  ASSERT_TRUE(after_preview.ok()) << after_preview.error();
  EXPECT_EQ(after_preview->passes_total, 2);
  EXPECT_EQ(after_preview->preview_spp, 4);
  auto preview = f.client->fetchDelta(id, f.base_job, 0);
  ASSERT_TRUE(preview.ok()) << preview.error();
  ASSERT_EQ(preview->pass, 0) << "the final pass landed before the preview could be fetched";
  EXPECT_FALSE(preview->final);
  const BakeSettings preview_settings = progressivePasses(f.scene.bake).front();
  EXPECT_EQ(preview->settings, preview_settings);
  EXPECT_EQ(preview_settings.max_hemisphere, f.scene.bake.max_hemisphere / 2);
  ASSERT_GT(preview->rects.size(), 0u);
  std::vector<RdmId> ids;
  for (const DeltaRect& r : preview->rects) ids.push_back(r.entry.id);
  EXPECT_EQ(mismatchedRects(*preview, bakeIds(edited, preview_settings, ids)), 0);

  auto final = f.client->fetchDelta(id, f.base_job, 1);
  for (int i = 0; i < 600 && !final.ok() && final.status().code() == StatusCode::kConflict; ++i) {
    (void)f.client->jobProgress(id, 1.0, 2);
    final = f.client->fetchDelta(id, f.base_job, 1);
  }
  ASSERT_TRUE(final.ok()) << final.error();
  EXPECT_TRUE(final->final);
  EXPECT_EQ(final->settings, f.scene.bake);
  ASSERT_EQ(final->rects.size(), preview->rects.size());  // the same plan, refined
  // The exact job's last pass equals a full bake of the new scene, RDM by RDM.
  EXPECT_EQ(mismatchedRects(*final, bakeIds(edited, f.scene.bake, ids)), 0);

  // One request brought every changed rect: applied to the base atlas it gives the job's own.
  auto done = f.client->jobProgress(id, 30.0);
  while (done.ok() && !done->terminal()) done = f.client->jobProgress(id, 30.0);
  ASSERT_TRUE(done.ok() && done->succeeded());
  auto base_page = decodeExr(
      test::must(f.client->download(f.base_job, "atlas.exr?page=0"), "download"), kRgbzChannels);
  auto job_page =
      decodeExr(test::must(f.client->download(id, "atlas.exr?page=0"), "download"), kRgbzChannels);
  ASSERT_TRUE(base_page.ok() && job_page.ok());
  Image patched_page = *base_page;
  for (const DeltaRect& r : final->rects) {
    for (int f = 0; f < 6; ++f) {
      const FaceTile& t = r.entry.faces[size_t(f)];
      if (t.page != 0) continue;
      const Image face = faceTexels(r.texels, f);
      for (int y = 0; y < face.height; ++y)
        for (int x = 0; x < face.width; ++x)
          for (int c = 0; c < 4; ++c) patched_page.at(t.x + x, t.y + y, c) = face.at(x, y, c);
    }
  }
  int differ = 0;
  for (const AtlasEntry& e : final->layout.entries) {
    for (const FaceTile& t : e.faces) {
      if (t.page != 0) continue;
      for (int y = t.y; y < t.y + e.id.size; ++y)
        for (int x = t.x; x < t.x + e.id.size; ++x)
          for (int c = 0; c < 4; ++c) differ += patched_page.at(x, y, c) != job_page->at(x, y, c);
    }
  }
  EXPECT_EQ(differ, 0);
  // The per-RDM endpoint reads the same store: one RDM equals its delta rect.
  const AtlasEntry& e = final->rects[0].entry;
  auto rdm = f.client->download(
      id, "rdms/" + std::to_string(e.id.slot.x) + "," + std::to_string(e.id.slot.y) + "," +
              std::to_string(e.id.slot.z) + "/" + std::to_string(e.id.level) + ".exr");
  ASSERT_TRUE(rdm.ok()) << rdm.error();
  EXPECT_EQ(decodeExr(*rdm, kRgbzChannels)->pixels, final->rects[0].texels.pixels);
}

TEST(ServerLive, DeltasThatDoNotChainAndStalePatchesGet409) {
  Fixture f;
  start(f, "refusals");
  // A second scene's job is no base for a delta of the first's.
  auto other = f.client->uploadScene(sceneToJson(f.scene));
  ASSERT_TRUE(other.ok());
  auto other_job = f.client->submitBake((*other)["id"], json::object());
  ASSERT_TRUE(other_job.ok());
  const std::string other_id = (*other_job)["id"];
  auto done = f.client->jobProgress(other_id, 30.0);
  while (done.ok() && !done->terminal()) done = f.client->jobProgress(other_id, 30.0);
  auto foreign = f.client->get("/v1/jobs/" + f.base_job + "/delta.bin?from=" + other_id);
  ASSERT_TRUE(foreign.ok());
  EXPECT_EQ(foreign->status, 409) << foreign->body;
  EXPECT_NE(foreign->body.find("index.json"), std::string::npos) << "says what to fetch instead";
  auto unknown = f.client->get("/v1/jobs/" + f.base_job + "/delta.bin?from=j0123456789abcdef");
  EXPECT_EQ(unknown->status, 404);
  auto no_from = f.client->get("/v1/jobs/" + f.base_job + "/delta.bin");
  EXPECT_EQ(no_from->status, 400);
  // A PATCH against a stale version.
  const Scene edited = withoutPawn(f.scene);
  ASSERT_TRUE(f.client->patchScene(f.scene_id, makeScenePatch(f.scene, edited, 1)).ok());
  auto stale = f.client->patchScene(f.scene_id, makeScenePatch(f.scene, edited, 1));
  ASSERT_FALSE(stale.ok());
  EXPECT_EQ(stale.status().code(), StatusCode::kConflict) << stale.error();
  // An empty PATCH creates no version.
  auto empty = f.client->patchScene(f.scene_id, makeScenePatch(edited, edited, 2));
  ASSERT_TRUE(empty.ok()) << empty.error();
  EXPECT_EQ((*empty)["version"], 2);
  // A pass that is not published yet is a 409 naming the pass.
  auto job = f.client->submitBake(f.scene_id, {{"mode", "exact"}});
  ASSERT_TRUE(job.ok());
  auto early = f.client->get("/v1/jobs/" + (*job)["id"].get<std::string>() +
                             "/delta.bin?from=" + f.base_job + "&pass=1");
  ASSERT_TRUE(early.ok());
  if (early->status != 200) {  // 200 only if the whole job already finished
    EXPECT_EQ(early->status, 409) << early->body;
  }
}

}  // namespace
}  // namespace rdm
