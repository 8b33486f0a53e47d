// The daemon's face light and noise outputs as a client sees them: a real `rdm serve` process
// on an ephemeral loopback port (docs/spec.md section 8.4), against the one-process bake.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <thread>

#include "face_light_expect.h"
#include "fresh_dir.h"
#include "rdm/atlas/noise_map.h"
#include "rdm/bake/bake.h"
#include "rdm/bake/bake_stats.h"
#include "rdm/bake/face_light.h"
#include "rdm/bake/rdm_source.h"
#include "rdm/base/file_util.h"
#include "rdm/scene/scene.h"
#include "rdm/scene/scene_patch.h"
#include "rdm/scene/world.h"
#include "rdm/service/client.h"
#include "server_fixtures.h"
#include "server_process.h"

namespace rdm {
namespace {

using test::chessJson;
using test::connectClient;
using test::expectProblem;
using test::ServerProcess;
using test::submit;
using test::waitSucceeded;

using nlohmann::json;

std::string freshDir(const std::string& name) {
  return test::freshTestDir("server_light", name);
}

LoadedAtlas downloadAtlas(BakeClient& c, const std::string& job) {
  return test::downloadAtlas(c, job, freshDir("atlas_" + job));
}

FaceLight downloadFaceLight(BakeClient& c, const std::string& job) {
  return test::downloadFaceLight(c, job, freshDir("light_" + job));
}

// A job asked for face light (docs/spec.md section 8.4) serves face_light.bin with the bits
// bakeFaceLight gives in one process; an exact job after an edit updates its base's light as
// updateFaceLight does (the viewer's rule); a job without it answers 404 naming the key.
TEST(ServerFaceLight, FullAndExactJobsServeTheInProcessBits) {
  const std::string dir = freshDir("face_light");
  ServerProcess server(dir, {"--threads", "2"});
  auto c = connectClient(server);
  const Scene v1 = *parseSceneJson(chessJson(2, 4));
  const std::string scene = test::must(c->uploadScene(sceneToJson(v1)), "upload")["id"];
  const std::string base = submit(*c, scene, {{"face_light", 4}});
  EXPECT_EQ(waitSucceeded(*c, base)["face_light"], 4);
  FaceLightOptions options;
  options.threads = 2, options.spp = 4;
  const VoxelWorld world1 = buildWorld(v1);
  FaceLight want = bakeFaceLight(world1, v1, options);
  test::expectSameFaceLight(want, downloadFaceLight(*c, base));

  const json edit =
      json::parse(R"({"base_version": 1, "edits": [{"at": [0, 1, 0], "block": null}]})");
  ASSERT_EQ(c->patch("/v1/scenes/" + scene, edit.dump())->status, 200);
  const Scene v2 = *applyScenePatch(v1, edit);
  const std::string exact =
      submit(*c, scene, {{"mode", "exact"}, {"base_job", base}, {"face_light", 4}});
  waitSucceeded(*c, exact);
  const std::vector<glm::ivec3> rebaked = updateFaceLight(world1, buildWorld(v2), v1.bake, want, 2);
  EXPECT_FALSE(rebaked.empty());
  want.scene_digest = faceLightSceneDigest(v2);
  test::expectSameFaceLight(want, downloadFaceLight(*c, exact));

  const std::string without = submit(*c, scene, json::object());
  waitSucceeded(*c, without);
  expectProblem(c->get("/v1/jobs/" + without + "/face_light.bin"), 404);
  expectProblem(c->post("/v1/scenes/" + scene + "/bakes", R"({"face_light": -1})"), 422,
                "face_light");

  // Without the key a job takes the scene's bake.face_light_spp; 0 asks for none.
  const std::string lit = test::must(c->uploadScene(chessJson(2, 4, 2)), "upload")["id"];
  EXPECT_EQ(waitSucceeded(*c, submit(*c, lit, json::object()))["face_light"], 2);
  EXPECT_EQ(waitSucceeded(*c, submit(*c, lit, {{"face_light", 0}}))["face_light"], 0);
}

// The face light counts in a job's progress (docs/api.md "progress"): estimated from the
// scene's exposed faces while the RDMs bake, then counted face by face; the fraction never
// reaches 1 before the light is written and never goes back.
TEST(ServerFaceLight, ProgressCountsTheFaceLightUntilItIsWritten) {
  const std::string dir = freshDir("face_light_progress");
  ServerProcess server(dir, {"--threads", "2"});
  auto c = connectClient(server);
  const std::string scene = test::must(c->uploadScene(chessJson(1, 4)), "upload")["id"];
  const std::string job = submit(*c, scene, {{"face_light", 32}});
  double last_fraction = 0.0;
  int face_light_polls = 0;
  json status;
  for (;;) {
    auto reply = c->get("/v1/jobs/" + job);
    ASSERT_EQ(reply->status, 200) << reply->body;
    status = json::parse(reply->body);
    const json& p = status["progress"];
    ASSERT_GE(p["fraction"].get<double>(), last_fraction);
    last_fraction = p["fraction"].get<double>();
    if (status["state"] != "running" && status["state"] != "queued") break;
    if (p["phase"] == "rdms") {
      EXPECT_GT(p["face_light_faces_total"].get<uint64_t>(), 0u);
    }
    if (p["phase"] == "face_light") {
      ++face_light_polls;
      EXPECT_LT(last_fraction, 1.0);
      EXPECT_LT(p["face_light_faces_done"].get<uint64_t>(),
                p["face_light_faces_total"].get<uint64_t>());
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_EQ(status["state"], "succeeded") << status.dump();
  EXPECT_GT(face_light_polls, 0) << "the face light phase was never seen";
  const json& p = status["progress"];
  EXPECT_EQ(p["fraction"], 1.0);
  EXPECT_TRUE(p["phase"].is_null());
  EXPECT_GT(p["face_light_faces_total"].get<uint64_t>(), 0u);
  EXPECT_EQ(p["face_light_faces_done"], p["face_light_faces_total"]);
}

// A full job's noise map and noise figures are those of the one-process bake (rdm bake's
// noise.exr and bake_report.json); an incremental job reports the figures of the RDMs it
// baked and has no noise map (404 saying why).
TEST(ServerNoise, FullJobsServeTheOneProcessNoiseMapAndFigures) {
  const std::string dir = freshDir("noise");
  ServerProcess server(dir, {"--threads", "2"});
  auto c = connectClient(server);
  const std::string scene_json = chessJson(2, 4);
  const std::string scene = test::must(c->uploadScene(scene_json), "upload")["id"];
  const std::string job = submit(*c, scene, json::object());
  const json done = waitSucceeded(*c, job);

  const Scene s = *parseSceneJson(scene_json);
  BakeOptions options;
  options.threads = 2;
  const BakeResult want = bakeScene(buildWorld(s), s.bake, options);
  BakeReport figures;
  summariseBake(want.rdms, figures);
  ASSERT_TRUE(done["noise"].is_object()) << done.dump();
  EXPECT_NEAR(done["noise"]["mean_relative_error"].get<double>(), figures.mean_relative_error,
              1e-12 * figures.mean_relative_error);  // summed in another order at most
  EXPECT_EQ(done["noise"]["max_relative_error"].get<double>(), figures.max_relative_error);
  const std::string local = freshDir("noise_local");
  ASSERT_TRUE(writeNoiseMaps(local, downloadAtlas(*c, job).layout, MemoryRdmSource(want.rdms)));
  auto served = c->download(job, "noise.exr");
  ASSERT_TRUE(served.ok()) << served.error();
  EXPECT_EQ(*served, *readFileToString(local + "/noise.exr"));

  const json edit =
      json::parse(R"({"base_version": 1, "edits": [{"at": [0, 1, 0], "block": null}]})");
  ASSERT_EQ(c->patch("/v1/scenes/" + scene, edit.dump())->status, 200);
  const std::string exact = submit(*c, scene, {{"mode", "exact"}, {"base_job", job}});
  EXPECT_TRUE(waitSucceeded(*c, exact)["noise"].is_object());
  expectProblem(c->get("/v1/jobs/" + exact + "/noise.exr"), 404);
}

}  // namespace
}  // namespace rdm
