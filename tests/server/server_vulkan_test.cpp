// The bake daemon on its Vulkan backend (`rdm serve --backend vulkan`, docs/spec.md section
// 8.4): a real daemon process on lavapipe, checked against the in-process Vulkan bake, its
// own full bakes after an edit, and a restart after SIGKILL.
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <thread>
#include <tuple>

#include "face_light_expect.h"
#include "fresh_dir.h"
#include "rdm/atlas/atlas.h"
#include "rdm/bake/face_light.h"
#include "rdm/bake/unit_checkpoint.h"
#include "rdm/base/file_util.h"
#include "rdm/image/exr_io.h"
#include "rdm/image/ktx2.h"
#include "rdm/scene/scene.h"
#include "rdm/service/client.h"
#include "rdm/vulkan/vulkan_bake.h"
#include "server_process.h"
#include "vulkan_bake_support.h"

namespace rdm {
namespace {

using nlohmann::json;
using test::connectClient;
using test::ServerProcess;
using test::submit;
using test::waitSucceeded;
namespace fs = std::filesystem;

std::string freshDir(const std::string& name) {
  return test::freshTestDir("server_vulkan", name);
}

// Chess with the naive estimator (the kernel's), without the face light.
Scene naiveChess(int spp, int hemisphere) {
  Scene s = *builtinScene("chess");
  s.bake.spp = spp, s.bake.max_hemisphere = hemisphere;
  s.bake.estimator = Estimator::kNaive;
  s.face_light_spp = 0;
  return s;
}

// The atlas one in-process Vulkan bake of the whole scene writes (docs/spec.md section 4).
std::string inProcessVulkanAtlas(const Scene& scene) {
  VoxelWorld world = buildWorld(scene);
  auto result = bakeSceneVulkan(world, scene.bake, VulkanBakeOptions{});
  if (!result) return "bake failed: " + result.error();
  std::vector<RdmId> ids;
  for (const RdmData& d : result->rdms) ids.push_back(d.id);
  std::vector<Image> pages = assembleAtlas(packCanonical(ids, storedFacesOf(world)), result->rdms);
  return *encodeExr(pages[0], kRgbzChannels);
}

// Small Vulkan calls, so a job takes many of them (the batch split must not show).
const std::vector<std::string> kVulkanFlags = {"--backend",           "vulkan", "--threads", "1",
                                               "--vulkan-call-paths", "20000"};

TEST(ServerVulkan, ResumedFullAndExactJobsMatchVulkanBakesBitForBit) {
  RDM_REQUIRE_VULKAN();
  const std::string dir = freshDir("cycle");
  const Scene scene = naiveChess(16, 8);
  std::string scene_id, job;
  size_t units_at_kill = 0, total = 0;
  {
    ServerProcess server(dir, kVulkanFlags);
    auto c = connectClient(server);
    scene_id = test::must(c->uploadScene(sceneToJson(scene)), "upload")["id"];
    job = submit(*c, scene_id, json::object());
    const std::string log = dir + "/jobs/" + job + "/" + kUnitLogFile;
    auto logged = [&] {  // the log appears with the first call's units; a torn tail is ignored
      auto bytes = readFileToString(log);
      return bytes ? readUnitLog(*bytes).size() : size_t(0);
    };
    for (int i = 0; i < 20000 && (total == 0 || units_at_kill == 0); ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
      json j = test::must(c->job(job), "job status");
      total = j["units"]["total"];
      EXPECT_EQ(j["backend"], "vulkan");
      EXPECT_TRUE(j["device"].is_string());
      units_at_kill = logged();
    }
    server.stop(SIGKILL);
    units_at_kill = logged();
    std::printf("[ server ] killed with %zu of %zu units on disk\n", units_at_kill, total);
    ASSERT_GT(units_at_kill, 0u);
    ASSERT_LT(units_at_kill, total);
  }
  ServerProcess server(dir, kVulkanFlags);
  auto c = connectClient(server);
  json done = waitSucceeded(*c, job);
  EXPECT_EQ(done["units"]["restored"].get<size_t>(), units_at_kill);
  EXPECT_EQ(*c->download(job, "atlas.exr"), inProcessVulkanAtlas(scene));

  // One block edit: the rook at (0, 1, 0) goes. `exact` (with its preview pass) re-bakes
  // what the kernel's recorded slot sets say and equals a full Vulkan bake of the new version.
  auto patched =
      c->patch("/v1/scenes/" + scene_id,
               "{\"base_version\": 1, \"edits\": [{\"at\": [0, 1, 0], \"block\": null}]}");
  ASSERT_EQ(patched->status, 200) << patched->body;
  const std::string exact = submit(*c, scene_id, {{"mode", "exact"}, {"base_job", job}});
  const std::string full = submit(*c, scene_id, json::object());
  json exact_done = waitSucceeded(*c, exact);
  const int n_exact = exact_done["rdms"]["rebaked"],
            n_full = waitSucceeded(*c, full)["rdms"]["rebaked"];
  std::printf("[ server ] Vulkan RDMs re-baked after a one-block edit: full %d, exact %d\n", n_full,
              n_exact);
  EXPECT_EQ(exact_done["passes"]["done"], 2);  // the preview, then the final pass
  EXPECT_GT(n_exact, 0);
  EXPECT_GT(n_full, n_exact);
  test::expectSameRdms(*c, full, exact);
}

// A Vulkan job found by a daemon restarted without its device fails, and its error (the
// client's to act on) names the device and what to do.
TEST(ServerVulkan, JobWhoseDeviceIsGoneFailsNamingIt) {
  RDM_REQUIRE_VULKAN();
  const std::string dir = freshDir("gone");
  std::string job;
  {
    ServerProcess server(dir, kVulkanFlags);
    auto c = connectClient(server);
    const std::string scene_id =
        test::must(c->uploadScene(sceneToJson(naiveChess(16, 8))), "upload")["id"];
    job = submit(*c, scene_id, json::object());
    server.stop(SIGKILL);  // seconds before the bake ends on lavapipe
  }
  ServerProcess server(dir, {"--backend", "cpu", "--threads", "1"});
  auto c = connectClient(server);
  auto ended = c->waitForJob(job, test::kJobWaitSeconds);
  ASSERT_TRUE(ended) << ended.error();
  EXPECT_EQ((*ended)["state"], "failed") << ended->dump(1);
  const std::string error = (*ended)["error"];
  EXPECT_NE(error.find("the Vulkan device '"), std::string::npos) << error;
  EXPECT_NE(error.find("has no Vulkan"), std::string::npos) << error;
  EXPECT_NE(error.find("submit it again"), std::string::npos) << error;
}

TEST(ServerVulkan, BakesEitherEstimatorAndRefusesAnotherDevicesBase) {
  RDM_REQUIRE_VULKAN();
  const std::string dir = freshDir("rules");
  std::string scene_id, cpu_job;
  {
    ServerProcess server(dir, {"--backend", "cpu", "--threads", "1"});
    auto c = connectClient(server);
    scene_id = test::must(c->uploadScene(sceneToJson(naiveChess(1, 4))), "upload")["id"];
    cpu_job = submit(*c, scene_id, json::object());
    EXPECT_EQ(waitSucceeded(*c, cpu_job)["backend"], "cpu");
  }
  ServerProcess server(dir, kVulkanFlags);
  auto c = connectClient(server);
  // Both estimators bake on the device.
  const std::string prefiltered =
      submit(*c, scene_id, json{{"settings", {{"estimator", "prefiltered"}}}});
  const json done = waitSucceeded(*c, prefiltered);
  EXPECT_EQ(done["backend"], "vulkan") << done.dump();
  // An exact job's base must have baked on the same backend and device.
  auto exact = c->post("/v1/scenes/" + scene_id + "/bakes",
                       json{{"mode", "exact"}, {"base_job", cpu_job}}.dump());
  ASSERT_TRUE(exact.ok());
  EXPECT_EQ(exact->status, 409) << exact->body;
  EXPECT_EQ(json::parse(exact->body).value("field", ""), "base_job");
}

// A job on the device traces its face light there (docs/spec.md section 3.2, "Backends"):
// the daemon's face_light.bin holds the bits of an in-process bake on the same device. On
// chess some faces' values differ between the device and the CPU (a float tie taking another
// branch; VulkanFaceLight.* bounds it: 5 of 47,568 on lavapipe, Mesa 22.3), which is what
// shows where the daemon traced them.
TEST(ServerVulkan, FaceLightHoldsTheInProcessDeviceBits) {
  RDM_REQUIRE_VULKAN();
  Scene scene = naiveChess(1, 4);
  scene.bake.max_bounces = 2;
  const std::string dir = freshDir("face_light");
  ServerProcess server(dir, kVulkanFlags);
  auto c = connectClient(server);
  const std::string scene_id = test::must(c->uploadScene(sceneToJson(scene)), "upload")["id"];
  const std::string job = submit(*c, scene_id, json{{"face_light", 2}});
  const json done = waitSucceeded(*c, job);
  EXPECT_EQ(done["backend"], "vulkan") << done.dump();
  auto baker = VulkanBaker::create("");
  ASSERT_TRUE(baker.ok()) << baker.error();
  VulkanFaceLightTracer tracer(**baker);
  FaceLightOptions options;
  options.spp = 2;
  const VoxelWorld world = buildWorld(scene);
  auto device = bakeFaceLightOn(tracer, world, scene, options);
  ASSERT_TRUE(device.ok()) << device.error();
  test::expectSameFaceLight(*device, test::downloadFaceLight(*c, job, freshDir("face_light_got")));
  const FaceLight cpu = bakeFaceLight(world, scene, options);
  size_t differ = 0;
  for (size_t s = 0; s < cpu.slots.size(); ++s)
    for (size_t f = 0; f < cpu.slots[s].light.size(); ++f)
      differ += encodeRgb9e5(cpu.slots[s].light[f]) != encodeRgb9e5(device->slots[s].light[f]);
  std::printf("[ server ] chess face light: %zu of %zu faces differ from the CPU's bits\n", differ,
              cpu.faceCount());
  EXPECT_GT(differ, 0u);
}

TEST(ServerVulkan, AutoPicksWhatTheCliPicks) {
  RDM_REQUIRE_VULKAN();
  const std::string dir = freshDir("auto");
  ServerProcess server(dir, {"--threads", "1"});  // --backend auto is the default
  auto c = connectClient(server);
  const std::string scene_id =
      test::must(c->uploadScene(sceneToJson(naiveChess(1, 4))), "upload")["id"];
  json done = waitSucceeded(*c, submit(*c, scene_id, json::object()));
  const BackendChoice want = resolveBakeBackend(BakeBackend::kAuto, "");
  EXPECT_EQ(done["backend"], bakeBackendName(want.backend)) << want.reason;
}

// Where a bc6h job on the Vulkan backend with "denoise" encodes and denoises, as the log
// says: `passes` ("vulkan", "auto") on `expected` ("vulkan", "cpu").
void expectResultPassesOn(const std::string& passes, const std::string& expected) {
  const std::string dir = freshDir("passes_" + passes), log = dir + ".log";
  ServerProcess server(
      dir,
      {"--backend", "vulkan", "--threads", "1", "--log-level", "info", "--result-passes", passes},
      log);
  auto c = connectClient(server);
  const std::string scene_id =
      test::must(c->uploadScene(sceneToJson(naiveChess(2, 8))), "upload")["id"];
  const std::string job = submit(*c, scene_id, {{"radiance", "bc6h"}, {"denoise", true}});
  const json done = waitSucceeded(*c, job);
  EXPECT_EQ(done["backend"], "vulkan");
  EXPECT_GT(done["timings"]["denoise_seconds"].get<double>(), 0.0);
  auto ktx2 = decodeKtx2(test::must(c->download(job, "atlas.ktx2"), "atlas.ktx2"));
  EXPECT_TRUE(ktx2.ok()) << ktx2.error();
  const std::string lines = readFileToString(log).value();
  for (const char* event : {"\"event\":\"bc6h_blocks\"", "\"event\":\"denoise\""}) {
    const size_t at = lines.find(event);
    ASSERT_NE(at, std::string::npos) << event << " not in " << lines;
    const std::string line = lines.substr(at, lines.find('\n', at) - at);
    EXPECT_NE(line.find("\"on\":\"" + expected + "\""), std::string::npos) << line;
  }
}

// A Vulkan job encodes its bc6h atlas and denoises on the device when asked (its blocks are
// the CPU encoder's, VulkanBc6h.*); by default only on a GPU, so on lavapipe on the CPU.
TEST(ServerVulkan, ResultPassesRunWhereAsked) {
  RDM_REQUIRE_VULKAN();
  expectResultPassesOn("vulkan", "vulkan");
  const auto devices = listVulkanDevices();
  ASSERT_TRUE(devices.ok() && !devices->empty());
  if ((*devices)[0].type == "cpu") expectResultPassesOn("auto", "cpu");
}

}  // namespace
}  // namespace rdm
