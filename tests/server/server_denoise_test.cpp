// The daemon's denoised jobs (docs/api.md "denoise", docs/denoise.md): a job asked for it
// serves the atlas the one-process denoiser writes from the same RDMs, reports the
// denoiser's time, and a request with a malformed flag is refused naming it. A real
// `rdm serve` on a loopback port.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "fresh_dir.h"
#include "rdm/atlas/atlas.h"
#include "rdm/atlas/atlas_json.h"
#include "rdm/bake/bake.h"
#include "rdm/bake/denoise.h"
#include "rdm/base/file_util.h"
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

// The atlas pages `rdm bake --denoise` writes for `scene_json` on `layout`'s tiles.
LoadedAtlas localDenoised(const std::string& scene_json, const AtlasLayout& layout,
                          const std::string& dir) {
  const Scene scene = *parseSceneJson(scene_json);
  BakeOptions options;
  options.threads = 2;
  const BakeResult result = bakeScene(buildWorld(scene), scene.bake, options);
  auto spill = RdmSpill::create(test::freshTestDir("server", "denoise_spill"));
  EXPECT_TRUE(spill.ok());
  DenoiseStats stats;
  EXPECT_TRUE(
      denoiseRdms(MemoryRdmSource(result.rdms), nullptr, **spill, DenoiseSettings{}, 2, stats));
  EXPECT_TRUE(writeAtlasOutputs(dir, layout, **spill).ok());
  return test::must(readAtlasOutputs(dir), "local atlas");
}

TEST(ServerDenoise, ADenoisedJobServesWhatTheOneProcessDenoiserWrites) {
  const std::string dir = test::freshTestDir("server", "denoise");
  ServerProcess server(dir, {"--threads", "2"});
  auto c = connectClient(server);
  const std::string scene_json = chessJson(1, 16);
  const std::string scene = test::must(c->uploadScene(scene_json), "upload")["id"];
  expectProblem(c->post("/v1/scenes/" + scene + "/bakes", "{\"denoise\": \"yes\"}"), 422,
                "denoise");
  const std::string plain = submit(*c, scene, json::object());
  const std::string denoised = submit(*c, scene, {{"denoise", true}});
  const json plain_done = waitSucceeded(*c, plain), done = waitSucceeded(*c, denoised);
  EXPECT_EQ(plain_done["denoise"], false);
  EXPECT_EQ(done["denoise"], true);
  EXPECT_GT(done["timings"]["denoise_seconds"].get<double>(), 0.0);
  EXPECT_EQ(plain_done["timings"]["denoise_seconds"].get<double>(), 0.0);
  for (const char* sub : {"/served", "/plain"}) std::filesystem::create_directories(dir + sub);
  const LoadedAtlas served = test::downloadAtlas(*c, denoised, dir + "/served");
  const LoadedAtlas unfiltered = test::downloadAtlas(*c, plain, dir + "/plain");
  const LoadedAtlas local = localDenoised(scene_json, served.layout, dir + "/local");
  EXPECT_TRUE(differingRdms(served, local).empty()) << "the daemon's denoised RDMs differ";
  EXPECT_FALSE(differingRdms(served, unfiltered).empty()) << "the filter changed nothing";
}

}  // namespace
}  // namespace rdm
