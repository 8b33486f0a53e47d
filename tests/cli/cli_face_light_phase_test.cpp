// The face light phase of `rdm bake` as a user sees it: its own progress, Ctrl-C stopping it
// with nothing written, and face_light.bin among the files the bake says it wrote.
#include <gtest/gtest.h>

#include <csignal>
#include <filesystem>

#include "cli_run.h"
#include "cli_spawn.h"
#include "rdm/bake/face_light.h"
#include "rdm/vulkan/vulkan_bake.h"
#include "test_requirements.h"

namespace rdm {
namespace {

const std::string kTiny = " --spp 1 --max-hemisphere 4 ";

// Chess at 4096 face light samples on one thread: minutes of face light after a bake of
// about a second, so the phase is certainly running when the test interrupts it.
std::vector<std::string> slowFaceLightBake(const std::string& dir) {
  return {"bake", "--scene",   "chess", "--spp", "1", "--max-hemisphere", "4", "--face-light",
          "4096", "--threads", "1",     "-o",    dir};
}

TEST(CliFaceLightPhase, ShowsItsProgressAndIsListedAmongTheFilesWritten) {
  const std::string dir = tempDir("fl_progress");
  CliResult r = runRdm("bake --scene chess" + kTiny + "--face-light 2 -o " + dir);
  ASSERT_EQ(r.code, 0) << r.err;
  // Not a terminal: plain lines, the first at 0 % before any work, the last at 100 %.
  EXPECT_TRUE(contains(r.err, "progress: face light 0.0% (0/80 slots)")) << r.err;
  EXPECT_TRUE(contains(r.err, "progress: face light 100.0% (80/80 slots)")) << r.err;
  EXPECT_LT(r.err.find("progress: 100.0% ("), r.err.find("progress: face light")) << r.err;
  EXPECT_TRUE(contains(r.out, "wrote " + dir +
                                  "/atlas.exr, index.json, index.txt, noise.exr, face_light.bin, "
                                  "rdms.bin, bake_report.json"))
      << r.out;
  EXPECT_TRUE(std::filesystem::exists(dir + "/face_light.bin"));
  CliResult quiet = runRdm("bake --scene chess" + kTiny + "--face-light 2 -q -o " + dir);
  ASSERT_EQ(quiet.code, 0) << quiet.err;
  EXPECT_FALSE(contains(quiet.err, "face light")) << quiet.err;
}

TEST(CliFaceLightPhase, ABakeWithoutFaceLightDoesNotListIt) {
  const std::string dir = tempDir("fl_none");
  CliResult r = runRdm("bake --scene chess" + kTiny + "--face-light 0 -q -o " + dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(contains(
      r.out,
      "wrote " + dir + "/atlas.exr, index.json, index.txt, noise.exr, rdms.bin, bake_report"))
      << r.out;
  EXPECT_FALSE(contains(r.out, "face_light.bin")) << r.out;
}

TEST(CliFaceLightPhase, ShardListsItsFaceLight) {
  const std::string dir = tempDir("fl_shard");
  CliResult r = runRdm("bake --scene chess" + kTiny + "--face-light 1 --shard 1/2 -q -o " + dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(contains(r.out, "wrote shard 1/2 to " + dir + ": shard.json, ")) << r.out;
  EXPECT_TRUE(contains(r.out, "RDM files, rdms.bin, face_light.bin")) << r.out;
}

// Exit 130 and nothing written, the output directory the bake created removed again.
TEST(CliFaceLightPhase, CtrlCStopsTheFaceLightAndWritesNothing) {
  const std::string dir = tempDir("fl_cancel"), log = tempDir("fl_cancel_log");
  const pid_t pid = spawnRdm(slowFaceLightBake(dir), log);
  ASSERT_GT(pid, 0);
  const bool started = waitForLog(log, "progress: face light", 120.0);
  kill(pid, SIGINT);
  const std::optional<int> status = waitForExit(pid, 60.0);
  auto text = readFileToString(log);
  ASSERT_TRUE(text.ok());
  ASSERT_TRUE(started) << *text;
  ASSERT_TRUE(status.has_value()) << "still baking 60 s after Ctrl-C:\n" << *text;
  ASSERT_TRUE(WIFEXITED(*status)) << "killed by signal " << WTERMSIG(*status);
  EXPECT_EQ(WEXITSTATUS(*status), 130) << *text;
  EXPECT_TRUE(contains(*text, "rdm bake: interrupted")) << *text;
  EXPECT_TRUE(contains(*text, "nothing was written to " + dir)) << *text;
  EXPECT_FALSE(contains(*text, "wrote ")) << *text;
  EXPECT_FALSE(std::filesystem::exists(dir)) << "the bake created it, so it removes it empty";
}

// A second Ctrl-C ends the process at once (the default action of SIGINT), still before any
// file is written.
TEST(CliFaceLightPhase, SecondCtrlCQuitsAtOnce) {
  const std::string dir = tempDir("fl_cancel2"), log = tempDir("fl_cancel2_log");
  const pid_t pid = spawnRdm(slowFaceLightBake(dir), log);
  ASSERT_GT(pid, 0);
  const bool started = waitForLog(log, "progress: face light", 120.0);
  kill(pid, SIGINT);
  const bool announced = waitForLog(log, "interrupted", 30.0);
  kill(pid, SIGINT);
  const std::optional<int> status = waitForExit(pid, 60.0);
  auto text = readFileToString(log);
  ASSERT_TRUE(text.ok());
  ASSERT_TRUE(started && announced) << *text;
  ASSERT_TRUE(status.has_value()) << "still baking 60 s after two Ctrl-C:\n" << *text;
  // The first stop may have finished before the second signal: then it exited 130.
  const bool quit = WIFSIGNALED(*status) && WTERMSIG(*status) == SIGINT;
  const bool stopped = WIFEXITED(*status) && WEXITSTATUS(*status) == 130;
  EXPECT_TRUE(quit || stopped) << *text;
  for (const char* f : {"/atlas.exr", "/index.json", "/face_light.bin", "/bake_report.json"})
    EXPECT_FALSE(std::filesystem::exists(dir + f)) << f;
}

}  // namespace
}  // namespace rdm

namespace rdm {
namespace {

// --backend vulkan traces the face light on the device with the RDMs (docs/vulkan.md, "Face
// light"): the same faces as the CPU's bake, each within the cross-backend tolerance of
// tests/vulkan/vulkan_face_light_test.cpp (all but 0.1 %), and its progress lines.
TEST(CliFaceLightPhase, TheVulkanBackendBakesTheFaceLightOnTheDevice) {
  RDM_TEST_REQUIRE(listVulkanDevices().ok() && !listVulkanDevices()->empty(), "a Vulkan device");
  const std::string cpu = tempDir("fl_cpu"), vk = tempDir("fl_vulkan");
  ASSERT_EQ(runRdm("bake --scene chess" + kTiny + "--face-light 2 -q --backend cpu -o " + cpu).code,
            0);
  CliResult r = runRdm("bake --scene chess" + kTiny + "--face-light 2 --backend vulkan -o " + vk);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(contains(r.err, "progress: face light 100.0% (80/80 slots)")) << r.err;
  auto a = readFaceLight(cpu + "/face_light.bin"), b = readFaceLight(vk + "/face_light.bin");
  ASSERT_TRUE(a.ok() && b.ok()) << (a.ok() ? b.error() : a.error());
  ASSERT_EQ(a->slots.size(), b->slots.size());
  size_t faces = 0, outside = 0;
  for (size_t s = 0; s < a->slots.size(); ++s) {
    ASSERT_EQ(a->slots[s].faces, b->slots[s].faces);
    for (size_t f = 0; f < a->slots[s].light.size(); ++f, ++faces) {
      const glm::vec3 d = glm::abs(a->slots[s].light[f] - b->slots[s].light[f]);
      const glm::vec3 tol = 1e-4f * glm::abs(a->slots[s].light[f]) + 1e-6f;
      outside += glm::any(glm::greaterThan(d, tol)) ? 1 : 0;
    }
  }
  EXPECT_LE(double(outside), 0.001 * double(faces)) << outside << " of " << faces;
}

}  // namespace
}  // namespace rdm
