// The bake daemon as a client sees it: a real `rdm serve` process on an ephemeral loopback
// port with its own data directory, driven over HTTP (docs/spec.md section 8).
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <thread>

#include "face_light_expect.h"
#include "fresh_dir.h"
#include "rdm/atlas/atlas.h"
#include "rdm/atlas/atlas_incremental.h"
#include "rdm/atlas/noise_map.h"
#include "rdm/bake/bake.h"
#include "rdm/bake/bake_stats.h"
#include "rdm/bake/shard.h"
#include "rdm/bake/unit_checkpoint.h"
#include "rdm/base/file_util.h"
#include "rdm/image/exr_io.h"
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
using test::texelsByRdm;
using test::waitSucceeded;

using nlohmann::json;
namespace fs = std::filesystem;

std::string freshDir(const std::string& name) {
  return test::freshTestDir("server", name);
}

// The atlas the CLI's one-process bake writes for the same scene (docs/spec.md section 4).
std::string referenceAtlas(const std::string& scene_json, int threads) {
  Scene s = *parseSceneJson(scene_json);
  VoxelWorld world = buildWorld(s);
  BakeOptions options;
  options.threads = threads;
  BakeResult result = bakeScene(world, s.bake, options);
  std::vector<RdmId> ids;
  for (const RdmData& d : result.rdms) ids.push_back(d.id);
  std::vector<Image> pages = assembleAtlas(packCanonical(ids, storedFacesOf(world)), result.rdms);
  return *encodeExr(pages[0], kRgbzChannels);
}

// Writes raw bytes on a fresh connection and returns the status line's code.
int rawRequest(int port, const std::string& bytes, std::string* response = nullptr) {
  int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(uint16_t(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) return close(fd), -1;
  if (send(fd, bytes.data(), bytes.size(), MSG_NOSIGNAL) < 0) return close(fd), -1;
  std::string reply;
  char buf[4096];
  for (ssize_t n; (n = recv(fd, buf, sizeof buf, 0)) > 0;) reply.append(buf, size_t(n));
  close(fd);
  if (response) *response = reply;
  return reply.size() > 12 ? std::atoi(reply.c_str() + 9) : -1;
}

// A job's index.json and atlas page 0, downloaded into a directory of their own and read back.
LoadedAtlas downloadAtlas(BakeClient& c, const std::string& job) {
  return test::downloadAtlas(c, job, freshDir("atlas_" + job));
}

// A job asked for half radiance (docs/spec.md section 8.4) writes the same RDMs as the float32
// job `float_job` of the same settings: R, G, B within half's rounding (relative 2^-11 of the
// value, plus half's smallest subnormal), Z exactly, in a smaller page.
void expectHalfAtlasMatches(BakeClient& c, const std::string& float_job,
                            const std::string& half_job) {
  EXPECT_EQ(waitSucceeded(c, half_job)["radiance"], "half");
  const LoadedAtlas full = downloadAtlas(c, float_job), half = downloadAtlas(c, half_job);
  EXPECT_EQ(full.layout.radiance, RadianceFormat::kFloat32);
  ASSERT_EQ(half.layout.radiance, RadianceFormat::kHalf);
  ASSERT_EQ(half.layout.entries.size(), full.layout.entries.size());
  for (const AtlasEntry& e : full.layout.entries) {
    const AtlasEntry* h = half.layout.find(e.id.slot, e.id.level);
    ASSERT_NE(h, nullptr);
    const Image a = rdmTexels(full, e), b = rdmTexels(half, *h);
    for (size_t i = 0; i < a.pixels.size(); ++i) {
      const float v = a.pixels[i];
      if (i % 4 == 3) {
        ASSERT_EQ(b.pixels[i], v) << "depth texel " << i / 4;
      } else {
        ASSERT_NEAR(b.pixels[i], v, std::abs(v) * 0x1p-11f + 0x1p-24f) << "texel " << i / 4;
      }
    }
  }
  EXPECT_LT(c.download(half_job, "atlas.exr")->size(), c.download(float_job, "atlas.exr")->size());
}

TEST(ServerApi, UploadBakePollDownload) {
  const std::string dir = freshDir("cycle");
  ServerProcess server(dir, {"--threads", "2"});
  ASSERT_GT(server.port(), 0);
  auto c = connectClient(server);
  EXPECT_EQ(c->get("/healthz")->status, 200);
  const std::string scene_json = chessJson(4, 8);
  const auto start = std::chrono::steady_clock::now();
  auto created = c->uploadScene(scene_json);
  ASSERT_TRUE(created.ok()) << created.error();
  const std::string scene = (*created)["id"];
  EXPECT_EQ((*created)["version"], 1);
  auto posted = c->post("/v1/scenes/" + scene + "/bakes", "{}");
  ASSERT_EQ(posted->status, 202);
  const std::string job = json::parse(posted->body)["id"];
  EXPECT_EQ(posted->header("Location"), "/v1/jobs/" + job);
  json done = waitSucceeded(*c, job);
  EXPECT_EQ(done["settings"]["estimator"], "prefiltered");
  auto atlas = c->download(job, "atlas.exr");
  ASSERT_TRUE(atlas.ok()) << atlas.error();
  const double cycle =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("[ server ] upload-bake-poll-download cycle (chess, spp 4, S <= 8): %.3f s\n", cycle);
  EXPECT_EQ(done["progress"]["fraction"], 1.0);
  EXPECT_EQ(done["rdms"]["rebaked"], done["rdms"]["scene"]);
  // Texels are held for the RDMs in flight only (docs/spec.md section 8.10): at most one
  // per roughness level of the slots the 2 workers bake.
  EXPECT_GE(done["rdms"]["held_peak"].get<int>(), 1);
  EXPECT_LE(done["rdms"]["held_peak"].get<int>(), 2 * 8);
  EXPECT_NE(done["effects"]["simulated"].get<std::string>().find("sun"), std::string::npos);
  EXPECT_EQ(*atlas, referenceAtlas(scene_json, 2));  // byte for byte the one-process bake
  auto index = c->download(job, "index.json");
  ASSERT_TRUE(index.ok());
  EXPECT_TRUE(parseIndexJson(*index).ok());
  EXPECT_TRUE(c->download(job, "index.txt").ok());
  expectProblem(c->get("/v1/jobs/" + job + "/atlas.exr?page=7"), 400, "page");
  // Conditional GETs.
  auto got = c->get("/v1/scenes/" + scene);
  EXPECT_EQ(got->header("ETag"), "\"1\"");
  EXPECT_EQ(c->get("/v1/scenes/" + scene, {{"If-None-Match", "\"0\", W/\"1\""}})->status, 304);
  auto a1 = c->get("/v1/jobs/" + job + "/atlas.exr");
  EXPECT_EQ(
      c->get("/v1/jobs/" + job + "/atlas.exr", {{"If-None-Match", a1->header("ETag")}})->status,
      304);
  // Listing, paging, metrics.
  const std::string job2 = submit(*c, scene, json::object());
  waitSucceeded(*c, job2);
  json page1 = json::parse(c->get("/v1/jobs?limit=1")->body);
  ASSERT_EQ(page1["jobs"].size(), 1u);
  EXPECT_EQ(page1["jobs"][0]["id"], job2);  // newest first
  json page2 = json::parse(c->get(page1["next"].get<std::string>())->body);
  EXPECT_EQ(page2["jobs"][0]["id"], job);
  const std::string metrics = c->get("/metrics")->body;
  for (const char* m :
       {"rdm_queue_depth 0", "rdm_jobs{state=\"succeeded\"} 2", "rdm_rays_traced_total ",
        "rdm_bake_seconds_total ", "rdm_http_requests_total{code=\"202\"} 2"}) {
    EXPECT_NE(metrics.find(m), std::string::npos) << m << "\n" << metrics;
  }
  // A quality preset in the request; the explicit keys win over it.
  auto draft = c->post("/v1/scenes/" + scene + "/bakes",
                       "{\"settings\": {\"quality\": \"draft\", \"spp\": 2}}");
  ASSERT_EQ(draft->status, 202) << draft->body;
  json draft_done = waitSucceeded(*c, json::parse(draft->body)["id"]);
  EXPECT_EQ(draft_done["settings"]["spp"], 2);
  EXPECT_EQ(draft_done["settings"]["max_bounces"], 2);
  expectHalfAtlasMatches(*c, job, submit(*c, scene, {{"radiance", "half"}}));
}

TEST(ServerApi, BadInputGetsProblemAndChangesNothing) {
  const std::string dir = freshDir("bad");
  ServerProcess server(dir, {"--threads", "1", "--token", "sesame", "--max-body", "200000",
                             "--max-grid", "16", "--max-spp", "64"});
  auto c = connectClient(server, "sesame");
  auto created = c->uploadScene(chessJson(2, 8));
  ASSERT_TRUE(created.ok()) << created.error();
  const std::string scene = (*created)["id"], path = "/v1/scenes/" + scene;
  auto state = [&] {
    return c->get("/v1/scenes")->body + c->get(path)->body + c->get("/v1/jobs")->body;
  };
  const std::string before = state();

  json base = json::parse(chessJson(2, 8));
  auto with = [&](const std::function<void(json&)>& edit) {
    json j = base;
    edit(j);
    return j.dump();
  };
  expectProblem(c->post("/v1/scenes", "{\"format\": \"rdm-scene\", "), 400);
  expectProblem(c->post("/v1/scenes", with([](json& j) { j["bogus"] = 1; })), 422, "bogus");
  expectProblem(c->post("/v1/scenes", with([](json& j) { j["placements"][3]["rot"] = 24; })), 422,
                "placements[3].rot");
  expectProblem(c->post("/v1/scenes", with([](json& j) { j["size"][0] = 300; })), 422, "size[0]");
  expectProblem(c->post("/v1/scenes", with([](json& j) { j["size"][2] = 32; })), 422,
                "size[2]");  // --max-grid
  expectProblem(c->post("/v1/scenes", with([](json& j) { j["bake"]["spp"] = 128; })), 422,
                "bake.spp");
  expectProblem(c->post("/v1/scenes", std::string(300000, ' ')), 413);
  expectProblem(c->post("/v1/scenes", "{}", "application/x-www-form-urlencoded"), 415);
  // Unknown and malformed ids.
  expectProblem(c->get("/v1/scenes/s0123456789abcdef"), 404);
  expectProblem(c->get("/v1/scenes/..%2f..%2fetc"), 404);
  expectProblem(c->get("/v1/jobs/j0123456789abcdef"), 404);
  expectProblem(c->get("/v1/jobs/j0123456789abcdef/atlas.exr"), 404);
  expectProblem(c->del("/v1/jobs/nonsense"), 404);
  expectProblem(c->post("/v1/scenes/s0123456789abcdef/bakes", "{}"), 404);
  // Bake requests.
  expectProblem(c->post(path + "/bakes", "{\"mode\": \"quick\"}"), 422, "mode");
  expectProblem(c->post(path + "/bakes", "{\"settings\": {\"spp\": 0}}"), 422, "settings.spp");
  expectProblem(c->post(path + "/bakes", "{\"settings\": {\"spp\": 65}}"), 422, "settings.spp");
  expectProblem(c->post(path + "/bakes", "{\"version\": 9}"), 422, "version");
  expectProblem(c->post(path + "/bakes", "{\"settings\": {\"quality\": \"best\"}}"), 422,
                "settings.quality");
  expectProblem(c->post(path + "/bakes", "{\"settings\": {\"estimator\": \"magic\"}}"), 422,
                "settings.estimator");
  expectProblem(c->post(path + "/bakes", "{\"radiance\": \"bf16\"}"), 422, "radiance");
  expectProblem(c->post(path + "/bakes", "{\"radiance\": 3}"), 422, "radiance");
  expectProblem(c->post(path + "/bakes", "{\"mode\": \"exact\"}"), 409, "base_job");  // no base yet
  // PATCH.
  expectProblem(c->patch(path, "{\"base_version\": 0, \"emission_scale\": 2}"), 409,
                "base_version");
  expectProblem(c->patch(path, "{\"base_version\": 1, \"colour\": 2}"), 422, "colour");
  expectProblem(
      c->patch(path, "{\"base_version\": 1, \"edits\": [{\"at\": [9, 0, 0], \"block\": null}]}"),
      422, "edits[0].at[0]");
  expectProblem(
      c->patch(path, "{\"base_version\": 1, \"palette\": {\"1\": {\"color\": [1, 2, 300]}}}"), 422,
      "palette[0].color[2]");
  // Auth.
  auto anonymous = connectClient(server);
  expectProblem(anonymous->get("/v1/scenes"), 401);
  expectProblem(connectClient(server, "wrong")->get(path), 401);
  EXPECT_EQ(anonymous->get("/healthz")->status, 200);
  // Bodies refused before they are read: chunked, compressed, unknown length.
  const std::string head =
      "POST /v1/scenes HTTP/1.1\r\nHost: x\r\nAuthorization: Bearer sesame\r\n"
      "Content-Type: application/json\r\n";
  std::string reply;
  EXPECT_EQ(rawRequest(server.port(),
                       head + "Transfer-Encoding: chunked\r\n\r\n2\r\n{}\r\n0\r\n\r\n", &reply),
            411);
  EXPECT_NE(reply.find("application/problem+json"), std::string::npos);
  EXPECT_EQ(
      rawRequest(server.port(), head + "Content-Encoding: gzip\r\nContent-Length: 2\r\n\r\n{}"),
      415);
  EXPECT_EQ(rawRequest(server.port(), head + "Content-Length: 99999999999\r\n\r\n"), 413);
  EXPECT_EQ(rawRequest(server.port(), head + "Connection: close\r\n\r\n{}"), 411);
  EXPECT_EQ(state(), before);
}

// The job limit and the base choice answer from the core's codes (docs/spec.md 8.1): kBusy is
// 429 with Retry-After, an unknown base_job 404 naming the field; a refused job leaves no trace.
TEST(ServerApi, JobLimitAnswers429AndUnknownBaseNamesTheField) {
  ServerProcess server(freshDir("limit"), {"--threads", "1", "--max-jobs", "1"});
  auto c = connectClient(server);
  const std::string scene = test::must(c->uploadScene(chessJson(4, 16)), "upload")["id"];
  const std::string path = "/v1/scenes/" + scene + "/bakes";
  // At 4,096 spp the first job runs for minutes: it is still unfinished when the second comes.
  const std::string first =
      test::must(c->submitBake(scene, {{"settings", {{"spp", 4096}}}}), "submit")["id"];
  auto refused = c->post(path, "{}");
  expectProblem(refused, 429);
  if (refused.ok()) {
    EXPECT_EQ(refused->header("Retry-After"), "5");
    EXPECT_EQ(json::parse(refused->body).value("type", ""),
              "https://rdm.invalid/problems/too-many-jobs");
  }
  EXPECT_EQ(json::parse(c->get("/v1/jobs")->body)["total"], 1);
  ASSERT_TRUE(c->del("/v1/jobs/" + first).ok());
  ASSERT_TRUE(c->waitForJob(first, test::kJobWaitSeconds).ok());
  expectProblem(c->post(path, "{\"mode\": \"fast\", \"base_job\": \"j0123456789abcdef\"}"), 404,
                "base_job");
}

// Scene versions do not pile up (docs/spec.md section 8.3): after many PATCHes only the
// newest SceneStore::kKeptVersions versions and those jobs need stay on disk; an old version
// answers 404 saying so (a kept but unreadable one 500), and the base of the next incremental
// job is still there.
TEST(ServerScenes, OldVersionsArePrunedButThoseJobsNeedStay) {
  for (const int kept : {8, 3}) {  // the default, and --max-versions 3
    SCOPED_TRACE(kept);
    const std::string dir = freshDir("prune" + std::to_string(kept));
    std::vector<std::string> args = {"--threads", "2"};
    if (kept != 8) args.insert(args.end(), {"--max-versions", std::to_string(kept)});
    ServerProcess server(dir, args);
    ASSERT_GT(server.port(), 0);
    auto c = connectClient(server);
    auto created = c->uploadScene(chessJson(1, 4));
    ASSERT_TRUE(created.ok()) << created.error();
    const std::string scene = (*created)["id"], path = "/v1/scenes/" + scene;
    auto posted = c->post(path + "/bakes", "{}");
    ASSERT_EQ(posted->status, 202);
    waitSucceeded(*c, json::parse(posted->body)["id"]);  // baked at version 1: the base
    for (int v = 1; v <= 20; ++v) {
      const std::string body = "{\"base_version\": " + std::to_string(v) +
                               ", \"emission_scale\": " + std::to_string(1.0 + 0.01 * v) + "}";
      ASSERT_EQ(c->patch(path, body)->status, 200) << v;
    }
    int files = 0;
    for (const auto& f : fs::directory_iterator(dir + "/scenes/" + scene))  // not the sidecars
      files += f.path().filename().string().rfind("v", 0) == 0 && f.path().extension() == ".json";
    EXPECT_EQ(files, kept + 1);  // the newest `kept` of 21, and version 1 of the base job
    EXPECT_EQ(c->get(path + "?version=1")->status, 200);
    auto gone = c->get(path + "?version=5");
    EXPECT_EQ(gone->status, 404);
    EXPECT_NE(gone->body.find("no longer kept"), std::string::npos) << gone->body;
    auto bake_gone = c->post(path + "/bakes", "{\"version\": 5}");  // the same answer
    EXPECT_EQ(bake_gone->status, 404);
    EXPECT_NE(bake_gone->body.find("no longer kept"), std::string::npos) << bake_gone->body;
    EXPECT_EQ(c->get(path + "?version=21")->status, 200);
    if (kept == 8) {  // a kept version, out of the memory cache, whose file is damaged: 500
      std::ofstream(dir + "/scenes/" + scene + "/v14.json") << "{ torn";
      auto unreadable = c->get(path + "?version=14");
      EXPECT_EQ(unreadable->status, 500);
      EXPECT_EQ(unreadable->body.find("no longer kept"), std::string::npos) << unreadable->body;
    }
    auto incremental = c->post(path + "/bakes", "{\"mode\": \"fast\"}");
    ASSERT_EQ(incremental->status, 202) << incremental->body;
    waitSucceeded(*c, json::parse(incremental->body)["id"]);
  }
}

TEST(ServerResume, KilledMidBakeResumesWithoutRedoingUnits) {
  const std::string dir = freshDir("resume");
  const std::string scene_json = chessJson(4, 16);  // 490 units of a few ms each
  std::string job;
  size_t units_at_kill = 0;
  {
    ServerProcess server(dir, {"--threads", "1"});
    auto c = connectClient(server);
    const std::string scene = test::must(c->uploadScene(scene_json), "upload")["id"];
    job = submit(*c, scene, json::object());
    const std::string log = dir + "/jobs/" + job + "/" + kUnitLogFile;
    auto logged = [&] {  // the log appears with the first unit; a torn tail does not count
      auto bytes = readFileToString(log);
      return bytes ? readUnitLog(*bytes).size() : size_t(0);
    };
    size_t total = 0;
    for (int i = 0; i < 2000 && (total == 0 || units_at_kill < total / 3); ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
      json j = test::must(c->job(job), "job status");
      total = j["units"]["total"];
      units_at_kill = logged();
    }
    expectProblem(c->get("/v1/jobs/" + job + "/atlas.exr"), 409);  // not there yet
    server.stop(SIGKILL);
    units_at_kill = logged();
    std::printf("[ server ] killed with %zu of %zu units on disk\n", units_at_kill, total);
    ASSERT_GT(units_at_kill, 0u);
    ASSERT_LT(units_at_kill, total);
  }
  ServerProcess server(dir, {"--threads", "1"});
  auto c = connectClient(server);
  json done = waitSucceeded(*c, job);
  ASSERT_TRUE(done.is_object());
  EXPECT_EQ(done["units"]["restored"].get<size_t>(), units_at_kill);
  EXPECT_LE(done["rdms"]["held_peak"].get<int>(), 8);  // restoring streams RDMs out too
  auto atlas = c->download(job, "atlas.exr");
  ASSERT_TRUE(atlas.ok());
  server.stop(SIGTERM);
  EXPECT_EQ(*atlas, referenceAtlas(scene_json, 2));
}

TEST(ServerIncremental, ExactEqualsFullRebakeAndFastRebakesLess) {
  const std::string dir = freshDir("incremental");
  ServerProcess server(dir, {"--threads", "2"});
  auto c = connectClient(server);
  const std::string scene = test::must(c->uploadScene(chessJson(4, 8)), "upload")["id"];
  const std::string base = submit(*c, scene, json::object());
  waitSucceeded(*c, base);
  // One block edit: the rook at (0, 1, 0) goes.
  auto patched =
      c->patch("/v1/scenes/" + scene,
               "{\"base_version\": 1, \"edits\": [{\"at\": [0, 1, 0], \"block\": null}]}");
  ASSERT_EQ(patched->status, 200) << patched->body;
  EXPECT_EQ(json::parse(patched->body)["changed_slots"], json::parse("[[0, 1, 0]]"));
  const std::string exact = submit(*c, scene, {{"mode", "exact"}, {"base_job", base}});
  const std::string fast = submit(*c, scene, {{"mode", "fast"}, {"base_job", base}});
  const std::string full = submit(*c, scene, json::object());
  const json exact_done = waitSucceeded(*c, exact);
  const int n_exact = exact_done["rdms"]["rebaked"];
  EXPECT_LE(exact_done["rdms"]["held_peak"].get<int>(), 2 * 8);
  const int n_fast = waitSucceeded(*c, fast)["rdms"]["rebaked"];
  const int n_full = waitSucceeded(*c, full)["rdms"]["rebaked"];
  std::printf("[ server ] RDMs re-baked after a one-block edit: full %d, exact %d, fast %d\n",
              n_full, n_exact, n_fast);
  EXPECT_GT(n_full, n_exact);
  EXPECT_GT(n_exact, n_fast);
  test::expectSameRdms(*c, full, exact);
  auto got = texelsByRdm(*c, exact);
  json delta = json::parse(c->get("/v1/jobs/" + exact + "/delta?from=" + base)->body);
  EXPECT_EQ(delta["added"].size(), 0u);
  EXPECT_EQ(delta["removed"].size(), 2u);  // the rook's level-7 and level-3 RDMs
  EXPECT_EQ(int(delta["changed"].size()), n_exact);
  const json& first = delta["changed"][0];
  const std::string rdm_path =
      "/v1/jobs/" + exact + "/rdms/" + std::to_string(int(first["slot"][0])) + "," +
      std::to_string(int(first["slot"][1])) + "," + std::to_string(int(first["slot"][2])) + "/" +
      std::to_string(int(first["level"])) + ".exr";
  auto one = c->get(rdm_path);
  ASSERT_EQ(one->status, 200) << one->body;
  Image img = *decodeExr(one->body, kRgbzChannels);
  auto key = std::make_tuple(int(first["slot"][0]), int(first["slot"][1]), int(first["slot"][2]),
                             int(first["level"]));
  EXPECT_EQ(img.pixels, got[key]);
}

TEST(ServerLoad, ConcurrentPollersSeeNoErrors) {
  const std::string dir = freshDir("load");
  ServerProcess server(dir, {"--threads", "1"});
  auto c = connectClient(server);
  const std::string scene = test::must(c->uploadScene(chessJson(4, 8)), "upload")["id"];
  const std::string base = submit(*c, scene, json::object());
  waitSucceeded(*c, base);
  ASSERT_EQ(c->patch("/v1/scenes/" + scene,
                     "{\"base_version\": 1, \"edits\": [{\"at\": [7, 1, 7], \"block\": null}]}")
                ->status,
            200);
  // A long full bake, then an incremental one that must overtake it (units interleave).
  const std::string job = submit(*c, scene, {{"settings", {{"spp", 32}, {"max_hemisphere", 16}}}});
  const std::string quick = submit(*c, scene, {{"mode", "exact"}, {"base_job", base}});
  std::atomic<bool> done{false};
  std::atomic<int> errors{0};
  std::vector<std::vector<double>> latencies(32);
  std::vector<std::thread> pollers;
  for (int t = 0; t < 32; ++t) {
    pollers.emplace_back([&, t] {
      auto client = connectClient(server);
      while (!done) {
        auto start = std::chrono::steady_clock::now();
        auto r = client->get("/v1/jobs/" + job);
        latencies[size_t(t)].push_back(
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
        if (!r.ok() || r->status != 200) {
          ++errors;
          continue;
        }
        std::string state = json::parse(r->body)["state"];
        if (state != "queued" && state != "running") done = true;
      }
    });
  }
  for (std::thread& t : pollers) t.join();
  std::vector<double> all;
  for (auto& l : latencies) all.insert(all.end(), l.begin(), l.end());
  std::sort(all.begin(), all.end());
  auto pct = [&](double p) {
    return 1e3 * all[std::min(all.size() - 1, size_t(p * double(all.size())))];
  };
  std::printf(
      "[ server ] 32 pollers, %zu GETs during a bake: p50 %.2f ms, p95 %.2f ms, p99 %.2f ms\n",
      all.size(), pct(0.50), pct(0.95), pct(0.99));
  EXPECT_EQ(errors.load(), 0);
  json long_job = test::must(c->job(job), "job status"), quick_job = waitSucceeded(*c, quick);
  EXPECT_EQ(long_job["state"], "succeeded");
  EXPECT_LT(quick_job["finished"].get<double>(), long_job["finished"].get<double>());
  std::printf("[ server ] exact job finished %.2f s after submission, inside a %.2f s full bake\n",
              quick_job["finished"].get<double>() - quick_job["created"].get<double>(),
              long_job["finished"].get<double>() - long_job["started"].get<double>());
}

}  // namespace
}  // namespace rdm
