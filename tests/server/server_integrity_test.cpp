// Stored data that proves itself, against a real `rdm serve` (docs/api.md, "Integrity"):
// a damaged file of the data directory is detected when it is read, answered as
// `corrupt-data` (or the job that would build on it fails naming it), and never served or
// copied; a torn scene file costs that version only.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "fresh_dir.h"
#include "rdm/base/file_util.h"
#include "rdm/base/hash.h"
#include "rdm/scene/scene.h"
#include "rdm/service/client.h"
#include "server_process.h"
#include "test_scenes.h"

namespace rdm {
namespace {

using nlohmann::json;
using test::connectClient;
using test::ServerProcess;
using test::submit;
using test::waitSucceeded;
namespace fs = std::filesystem;

std::string freshDir(const std::string& name) {
  return test::freshTestDir("integrity", name);
}

void flipBit(const std::string& path, uint64_t at) {
  std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
  ASSERT_TRUE(f.good()) << path;
  f.seekg(std::streamoff(at));
  char byte = 0;
  f.read(&byte, 1);
  byte = char(byte ^ 0x08);
  f.seekp(std::streamoff(at));
  f.write(&byte, 1);
}

void truncateFile(const std::string& path) {
  auto read = readFileToString(path);
  const std::string bytes = read ? *read : std::string();
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes.substr(0, bytes.size() / 2);
}

// A problem+json answer of `status` whose type ends in `slug`.
void expectProblem(const Expected<HttpReply>& r, int status, const std::string& slug) {
  ASSERT_TRUE(r.ok()) << r.error();
  EXPECT_EQ(r->status, status) << r->body;
  EXPECT_EQ(r->header("Content-Type"), "application/problem+json") << r->body;
  const json j = json::parse(r->body, nullptr, false);
  ASSERT_TRUE(j.is_object()) << r->body;
  const std::string type = j.value("type", "");
  EXPECT_EQ(type.substr(type.rfind('/') + 1), slug) << r->body;
}

TEST(ServerIntegrity, DamagedResultFilesAreNeverServedOrBuiltUpon) {
  const std::string dir = freshDir("results");
  ServerProcess server(dir, {"--threads", "2"});
  auto c = connectClient(server);
  const std::string scene = test::must(c->uploadScene(test::tinyChess(1, 4, 3)), "upload")["id"];
  const std::string base = submit(*c, scene, json::object());
  waitSucceeded(*c, base);
  const std::string out = dir + "/jobs/" + base + "/out";
  ASSERT_TRUE(fs::exists(out + "/checksums.json"));

  // An intact file's ETag is its content checksum (XXH3 64), and a 304 answers it.
  auto atlas = c->get("/v1/jobs/" + base + "/atlas.exr");
  ASSERT_TRUE(atlas.ok() && atlas->status == 200);
  EXPECT_EQ(atlas->header("ETag"), "\"" + contentHashHex(atlas->body) + "\"");
  EXPECT_EQ(
      c->get("/v1/jobs/" + base + "/atlas.exr", {{"If-None-Match", atlas->header("ETag")}})->status,
      304);
  auto index = c->get("/v1/jobs/" + base + "/index.json");
  ASSERT_TRUE(index.ok() && index->status == 200);
  EXPECT_EQ(index->header("ETag"), "\"" + contentHashHex(index->body) + "\"");

  // A flipped bit in the per-RDM store (inside the last RDM's texels): an exact job that
  // would copy that RDM fails naming the damage; it never succeeds with the bit.
  const std::string store = out + "/rdms.store";
  flipBit(store, fs::file_size(store) - 64);
  const std::string exact = submit(*c, scene, {{"mode", "exact"}, {"base_job", base}});
  auto ended = c->waitForJob(exact, test::kJobWaitSeconds);
  ASSERT_TRUE(ended.ok()) << ended.error();
  EXPECT_EQ((*ended)["state"], "failed") << ended->dump(1);
  const std::string error =
      (*ended)["error"].is_string() ? (*ended)["error"].get<std::string>() : "";
  EXPECT_NE(error.find("checksum"), std::string::npos) << error;
  expectProblem(c->get("/v1/jobs/" + exact + "/atlas.exr"), 409, "conflict");

  // A flipped bit in atlas.exr: the problem, not the bytes; the file is moved aside and
  // stays an answer of damage. Other files of the job are still served.
  flipBit(out + "/atlas.exr", fs::file_size(out + "/atlas.exr") / 2);
  expectProblem(c->get("/v1/jobs/" + base + "/atlas.exr"), 500, "corrupt-data");
  EXPECT_TRUE(fs::exists(out + "/atlas.exr.corrupt"));
  EXPECT_FALSE(fs::exists(out + "/atlas.exr"));
  expectProblem(c->get("/v1/jobs/" + base + "/atlas.exr"), 500, "corrupt-data");
  EXPECT_EQ(c->get("/v1/jobs/" + base + "/index.txt")->status, 200);

  // A torn index.json: every route that reads it answers the damage.
  truncateFile(out + "/index.json");
  expectProblem(c->get("/v1/jobs/" + base + "/index.json"), 500, "corrupt-data");
}

TEST(ServerIntegrity, TornSceneFilesCostOneVersionAndNeverTheScene) {
  const std::string dir = freshDir("scenes");
  std::string scene;
  {
    ServerProcess server(dir, {});
    auto c = connectClient(server);
    scene = test::must(c->uploadScene(test::tinyChess(1, 4, 3)), "upload")["id"];
    auto patched =
        c->patch("/v1/scenes/" + scene, "{\"base_version\": 1, \"emission_scale\": 1.5}");
    ASSERT_TRUE(patched.ok() && patched->status == 200) << (patched.ok() ? patched->body : "");
  }
  const std::string sdir = dir + "/scenes/" + scene, path = "/v1/scenes/" + scene;
  truncateFile(sdir + "/v2.json");
  {
    ServerProcess server(dir, {});
    auto c = connectClient(server);
    EXPECT_EQ(c->get(path + "?version=1")->status, 200);
    expectProblem(c->get(path + "?version=2"), 500, "corrupt-data");
    auto current = c->get(path);
    expectProblem(current, 500, "corrupt-data");
    EXPECT_NE(current->body.find("version 2"), std::string::npos) << current->body;
    const json list = json::parse(c->get("/v1/scenes")->body);
    ASSERT_EQ(list["scenes"].size(), 1u);
    EXPECT_EQ(list["scenes"][0]["id"], scene);
  }
  fs::copy_file(sdir + "/v1.json", sdir + "/v2.json", fs::copy_options::overwrite_existing);
  fs::remove(sdir + "/v2.json.xxh3");  // v2 now holds v1's scene, unverified, as before checksums
  truncateFile(sdir + "/meta.json");
  for (int restart = 0; restart < 2; ++restart) {  // rebuilt once, then read as written
    ServerProcess server(dir, {});
    auto c = connectClient(server);
    auto got = c->get(path);
    ASSERT_TRUE(got.ok());
    EXPECT_EQ(got->status, 200) << got->body;
    EXPECT_EQ(got->header("X-Scene-Version"), "2");
    EXPECT_EQ(c->get(path + "?version=1")->status, 200);
  }
}

}  // namespace
}  // namespace rdm
