// The daemon's bc6h atlases (docs/api.md "radiance", docs/bc6h.md "Incremental atlases"): a job
// asked for bc6h serves atlas.ktx2 and depth.exr, byte for byte what the one-process bake
// encodes; an incremental job copies the blocks of the tiles it keeps from its base and
// still writes the bytes a whole encode gives. A real `rdm serve` on a loopback port.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <set>
#include <string>
#include <tuple>

#include "fresh_dir.h"
#include "rdm/atlas/atlas.h"
#include "rdm/atlas/atlas_json.h"
#include "rdm/bake/bake.h"
#include "rdm/base/file_util.h"
#include "rdm/image/exr_io.h"
#include "rdm/image/ktx2.h"
#include "rdm/scene/scene.h"
#include "rdm/scene/world.h"
#include "rdm/service/client.h"
#include "server_fixtures.h"
#include "server_process.h"

namespace rdm {
namespace {

using nlohmann::json;
using test::chessJson;
using test::connectClient;
using test::expectProblem;
using test::ServerProcess;
using test::submit;
using test::waitSucceeded;

// What the one-process bake writes as page 0's atlas.ktx2 for `scene_json` on `layout`'s tiles.
std::string localKtx2(const std::string& scene_json, const AtlasLayout& layout,
                      const std::string& dir) {
  const Scene scene = *parseSceneJson(scene_json);
  BakeOptions options;
  options.threads = 2;
  const BakeResult result = bakeScene(buildWorld(scene), scene.bake, options);
  EXPECT_TRUE(writeAtlasOutputs(dir, layout, result.rdms).ok());
  return test::must(readFileToString(dir + "/" + atlasKtx2FileName(0)), "local atlas.ktx2");
}

AtlasLayout layoutOf(BakeClient& c, const std::string& job) {
  return parseIndexJson(test::must(c.download(job, "index.json"), "index.json")).value();
}

size_t blockAt(const Ktx2Image& image, int x, int y) {
  return (size_t(y / 4) * size_t((image.width + 3) / 4) + size_t(x / 4)) * 16;
}

// Blocks of every tile `next` keeps from `base` (same RDM, place and scale) whose RDM the
// delta does not list as re-baked: each the base's bytes. Returns how many were compared.
size_t expectKeptBlocksCopied(const AtlasLayout& base, const AtlasLayout& next,
                              const Ktx2Image& base_page, const Ktx2Image& next_page,
                              const std::set<std::tuple<int, int, int, int>>& rebaked) {
  size_t compared = 0;
  for (const AtlasEntry& e : next.entries) {
    if (rebaked.count({e.id.slot.x, e.id.slot.y, e.id.slot.z, e.id.level})) continue;
    const AtlasEntry* old = base.find(e.id.slot, e.id.level);
    if (!old || old->id.size != e.id.size) continue;
    const int span = std::max(e.id.size, 4);
    for (int f = 0; f < 6; ++f) {
      const FaceTile& t = e.faces[size_t(f)];
      if (t.page != 0 || !(t == old->faces[size_t(f)])) continue;
      for (int y = t.y; y < t.y + span; y += 4)
        for (int x = t.x; x < t.x + span; x += 4, ++compared)
          EXPECT_EQ(0, std::memcmp(&next_page.data[blockAt(next_page, x, y)],
                                   &base_page.data[blockAt(base_page, x, y)], 16))
              << "block at " << x << "," << y;
    }
  }
  return compared;
}

TEST(ServerBc6h, JobsServeBc6hAndIncrementalJobsCopyTheBlocksTheyKeep) {
  const std::string dir = test::freshTestDir("server", "bc6h");
  ServerProcess server(dir, {"--threads", "2"});
  auto c = connectClient(server);
  const std::string scene_json = chessJson(4, 8);
  const std::string scene = test::must(c->uploadScene(scene_json), "upload")["id"];
  const std::string base = submit(*c, scene, {{"radiance", "bc6h"}});
  const json done = waitSucceeded(*c, base);
  EXPECT_EQ(done["radiance"], "bc6h");
  EXPECT_EQ(done["links"]["atlas"], "/v1/jobs/" + base + "/atlas.ktx2");
  expectProblem(c->get("/v1/jobs/" + base + "/atlas.exr"), 404);
  const AtlasLayout base_layout = layoutOf(*c, base);
  EXPECT_EQ(base_layout.radiance, RadianceFormat::kBc6h);
  EXPECT_TRUE(blockAligned(base_layout));
  const std::string base_bytes = test::must(c->download(base, "atlas.ktx2"), "atlas.ktx2");
  EXPECT_EQ(base_bytes, localKtx2(scene_json, base_layout, dir + "/local_base"));
  EXPECT_TRUE(decodeExr(test::must(c->download(base, "depth.exr"), "depth.exr"), {"Z"}).ok());

  ASSERT_EQ(c->patch("/v1/scenes/" + scene,
                     "{\"base_version\": 1, \"edits\": [{\"at\": [0, 1, 0], \"block\": null}]}")
                ->status,
            200);
  const std::string next =
      submit(*c, scene, {{"mode", "exact"}, {"base_job", base}, {"radiance", "bc6h"}});
  waitSucceeded(*c, next);
  const AtlasLayout next_layout = layoutOf(*c, next);
  EXPECT_TRUE(blockAligned(next_layout));
  const std::string next_bytes = test::must(c->download(next, "atlas.ktx2"), "atlas.ktx2");
  const std::string edited_json = c->get("/v1/scenes/" + scene)->body;
  EXPECT_EQ(next_bytes, localKtx2(edited_json, next_layout, dir + "/local_next"));
  const json delta = json::parse(c->get("/v1/jobs/" + next + "/delta?from=" + base)->body);
  std::set<std::tuple<int, int, int, int>> rebaked;
  for (const json& r : delta["changed"])
    rebaked.insert(std::make_tuple(r["slot"][0].get<int>(), r["slot"][1].get<int>(),
                                   r["slot"][2].get<int>(), r["level"].get<int>()));
  ASSERT_FALSE(rebaked.empty());
  const size_t kept = expectKeptBlocksCopied(base_layout, next_layout, *decodeKtx2(base_bytes),
                                             *decodeKtx2(next_bytes), rebaked);
  const size_t blocks = next_bytes.size() / 16;
  std::printf(
      "[ server ] bc6h incremental job after a one-block edit: %zu RDMs re-baked, %zu of "
      "about %zu blocks kept from the base\n",
      rebaked.size(), kept, blocks);
  EXPECT_GT(kept, blocks / 10);  // measured 345 of 1,264 (chess 4 spp, S <= 8, exact mode)
}

}  // namespace
}  // namespace rdm
