// `rdm patch` and `rdm submit SCENE --scene-id`: a scene on a real daemon changed by one
// PATCH of the difference, and the 409 that names why no base job fits.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "cli_run.h"
#include "rdm/base/file_util.h"
#include "rdm/service/client.h"
#include "server_process.h"

namespace rdm {
namespace {

using nlohmann::json;

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

std::string line(const std::string& out, const std::string& head) {
  const size_t at = out.find(head);
  if (at == std::string::npos) return {};
  return out.substr(at + head.size(), out.find('\n', at) - at - head.size());
}

json furnace(const std::string& dir) {
  EXPECT_EQ(runRdm("scene --scene furnace -o " + dir + "/furnace.json").code, 0);
  return json::parse(*readFileToString(dir + "/furnace.json"));
}

void write(const std::string& path, const json& j) {
  std::ofstream(path) << j.dump();
}

class CliPatch : public testing::Test {
 protected:
  void SetUp() override {
    dir_ = tempDir("patch");
    std::filesystem::create_directories(dir_);
    server_ = std::make_unique<test::ServerProcess>(dir_ + "/data",
                                                    std::vector<std::string>{"--threads", "1"});
    ASSERT_GT(server_->port(), 0);
    at_ = " --server " + server_->url();
  }
  json jobStatus(const std::string& job) {
    CliResult fetched = runRdm("fetch " + job + at_ + " -o " + dir_ + "/" + job);
    EXPECT_EQ(fetched.code, 0) << fetched.err;
    return json::parse(runRdm("status " + job + at_ + " --json").out);
  }
  std::string dir_, at_;
  std::unique_ptr<test::ServerProcess> server_;
};

TEST_F(CliPatch, SubmitWithSceneIdSendsTheDifferenceAndBakesThatVersion) {
  json scene = furnace(dir_);
  CliResult first = runRdm("submit " + dir_ + "/furnace.json" + at_);
  ASSERT_EQ(first.code, 0) << first.err;
  const std::string scene_id = line(first.out, "scene "), base = line(first.out, "job ");
  EXPECT_EQ(jobStatus(base)["state"], "succeeded");

  scene["sky"]["zenith"] = {10.0, 10.0, 10.0};  // a brighter sky: every RDM is re-lit
  write(dir_ + "/bright.json", scene);
  CliResult exact =
      runRdm("submit " + dir_ + "/bright.json --scene-id " + scene_id + " --mode exact" + at_);
  ASSERT_EQ(exact.code, 0) << exact.err;
  EXPECT_TRUE(contains(exact.out, "version 2: every slot re-lit, sky")) << exact.out;
  const json status = jobStatus(line(exact.out, "job "));
  EXPECT_EQ(status["scene_version"], 2);
  EXPECT_GT(status["rdms"]["rebaked"].get<long long>(), 0) << status;

  CliResult same = runRdm("patch " + scene_id + " " + dir_ + "/bright.json" + at_);
  ASSERT_EQ(same.code, 0) << same.err;
  EXPECT_TRUE(contains(same.out, "unchanged at version 2")) << same.out;
}

TEST_F(CliPatch, PatchDocumentsAndScenesBothWork) {
  furnace(dir_);
  CliResult up = runRdm("submit " + dir_ + "/furnace.json" + at_);
  ASSERT_EQ(up.code, 0) << up.err;
  const std::string scene_id = line(up.out, "scene ");
  write(dir_ + "/edit.json", {{"edits", {{{"at", {0, 0, 0}}, {"block", "white"}}}}});
  CliResult edit = runRdm("patch " + scene_id + " " + dir_ + "/edit.json" + at_);
  ASSERT_EQ(edit.code, 0) << edit.err;
  EXPECT_TRUE(contains(edit.out, "version 2: 1 slot changed")) << edit.out;
  // Back to the built-in scene: the block added by the edit goes again.
  CliResult back = runRdm("patch " + scene_id + " furnace" + at_);
  ASSERT_EQ(back.code, 0) << back.err;
  EXPECT_TRUE(contains(back.out, "version 3: 1 slot changed")) << back.out;

  write(dir_ + "/stale.json", {{"base_version", 1}, {"edits", json::array()}});
  CliResult stale = runRdm("patch " + scene_id + " " + dir_ + "/stale.json" + at_);
  EXPECT_EQ(stale.code, 1);
  EXPECT_TRUE(contains(stale.err, "409")) << stale.err;
  CliResult bad = runRdm("patch " + scene_id + " " + dir_ + "/none.json" + at_);
  EXPECT_NE(bad.code, 0);
  EXPECT_TRUE(contains(bad.err, "none.json")) << bad.err;
}

TEST_F(CliPatch, ExactBakeWithOtherSettingsNamesWhatDiffers) {
  furnace(dir_);
  CliResult up = runRdm("submit " + dir_ + "/furnace.json" + at_);
  ASSERT_EQ(up.code, 0) << up.err;
  EXPECT_EQ(jobStatus(line(up.out, "job "))["state"], "succeeded");
  auto client = BakeClient::connect(server_->url());
  ASSERT_TRUE(client.ok()) << client.error();
  const json request = {{"mode", "exact"}, {"settings", {{"spp", 8}}}};
  auto reply = (*client)->post("/v1/scenes/" + line(up.out, "scene ") + "/bakes", request.dump());
  ASSERT_TRUE(reply.ok()) << reply.error();
  EXPECT_EQ(reply->status, 409);
  EXPECT_TRUE(contains(reply->body, "settings.spp 64 there, 8 asked")) << reply->body;
  EXPECT_FALSE(contains(reply->body, "run a full bake first")) << reply->body;
}

}  // namespace
}  // namespace rdm
