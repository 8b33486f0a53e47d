// The rdm command as a user runs it: separate processes, real files.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>

#include <csignal>
#include <nlohmann/json.hpp>
#include "cli_run.h"
#include "cli_spawn.h"
#include "rdm/atlas/atlas.h"
#include "rdm/atlas/slot_sets_file.h"
#include "rdm/bake/face_light.h"
#include "rdm/base/file_util.h"
#include "rdm/image/exr_io.h"
#include "rdm/scene/scene.h"
#include "server_process.h"

namespace rdm {
namespace {

int run(const std::string& args) {
  std::string cmd = std::string(RDM_BINARY) + " " + args + " > /dev/null 2>&1";
  int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(Cli, BakeWritesAtlasWithFiniteTexels) {
  std::string dir = tempDir("bake");
  ASSERT_EQ(run("bake --scene island --spp 2 --max-hemisphere 8 --quiet -o " + dir), 0);
  for (const char* f : {"/atlas.exr", "/index.json", "/index.txt", "/bake_report.json"}) {
    EXPECT_TRUE(std::filesystem::exists(dir + f)) << f;
  }
  auto atlas = readExr(dir + "/atlas.exr", kRgbzChannels);
  ASSERT_TRUE(atlas.ok()) << atlas.error();
  for (float v : atlas->pixels) ASSERT_TRUE(std::isfinite(v));
}

TEST(Cli, ShardsMergeToTheOneProcessBakeByteForByte) {
  const std::string settings = "--scene chess --spp 2 --max-hemisphere 8 --face-light 2 --quiet";
  std::string whole = tempDir("whole"), merged = tempDir("merged");
  ASSERT_EQ(run("bake " + settings + " -o " + whole), 0);
  std::vector<std::string> dirs;
  std::string shards;
  for (int i = 0; i < 3; ++i) {
    dirs.push_back(tempDir("shard" + std::to_string(i)));
    ASSERT_EQ(
        run("bake " + settings + " --threads 1 --shard " + std::to_string(i) + "/3 -o " + dirs[i]),
        0);
    shards += " " + dirs[i];
  }
  ASSERT_EQ(run("merge" + shards + " -o " + merged), 0);
  for (const char* f :
       {"/atlas.exr", "/index.json", "/index.txt", "/face_light.bin", "/rdms.bin"}) {
    EXPECT_EQ(*readFileToString(whole + f), *readFileToString(merged + f)) << f;
  }
  // Two of three shards: refused as incomplete.
  CliResult partial = runRdm("merge " + dirs[0] + " " + dirs[1] + " -o " + tempDir("partial"));
  EXPECT_EQ(partial.code, 1);
  EXPECT_TRUE(contains(partial.err, "shard")) << partial.err;
  // Face light in some shards only: refused, naming a shard without it, writing nothing.
  std::filesystem::remove(dirs[2] + "/face_light.bin");
  CliResult mixed = runRdm("merge" + shards + " -o " + tempDir("mixed"));
  EXPECT_EQ(mixed.code, 1);
  EXPECT_TRUE(contains(mixed.err, dirs[2] + " has no face_light.bin")) << mixed.err;
  EXPECT_FALSE(std::filesystem::exists(tempDir("mixed") + "/atlas.exr"));
}

// rdm diff compares RDM by RDM: bakes on 1 and 2 threads are identical, another seed is not, and an
// unreadable atlas is a failure naming the file.
TEST(Cli, DiffComparesAtlasesRdmByRdm) {
  const std::string settings = "--scene chess --spp 2 --max-hemisphere 8 --quiet";
  const std::string a = tempDir("diff_a"), b = tempDir("diff_b"), c = tempDir("diff_c");
  ASSERT_EQ(run("bake " + settings + " --threads 1 -o " + a), 0);
  ASSERT_EQ(run("bake " + settings + " --threads 2 -o " + c), 0);
  ASSERT_EQ(run("bake " + settings + " --seed 2 -o " + b), 0);
  CliResult same = runRdm("diff " + a + " " + c);
  EXPECT_EQ(same.code, 0) << same.out << same.err;
  EXPECT_TRUE(contains(same.out, "identical: ")) << same.out;
  CliResult differ = runRdm("diff " + a + " " + b);
  EXPECT_EQ(differ.code, 1);
  EXPECT_TRUE(contains(differ.out, "RDM(s) differ")) << differ.out;
  CliResult missing = runRdm("diff " + a + " " + tempDir("diff_none"));
  EXPECT_EQ(missing.code, 1);
  EXPECT_TRUE(contains(missing.err, "index.json")) << missing.err;
}

TEST(Cli, BadInputGetsClearErrorsAndExitCodes) {
  const std::string x = tempDir("x");
  EXPECT_EQ(run("bake --scene nosuch -o " + x), 1);
  EXPECT_EQ(run("bake --scene chess --spp 0 -o " + x), 2);  // a usage error, as in render
  EXPECT_EQ(run("bake --scene chess --bogus -o " + x), 2);
  EXPECT_EQ(run("bake --scene chess"), 2);
  EXPECT_EQ(run("bake --scene chess --shard 3/3 -o " + x), 2);
  EXPECT_EQ(run("frobnicate"), 2);
  EXPECT_FALSE(std::filesystem::exists(x));  // nothing written for refused input
}

TEST(Cli, SceneExportRoundTripsThroughBake) {
  std::string dir = tempDir("export");
  std::filesystem::create_directories(dir);
  ASSERT_EQ(run("scene --scene furnace -o " + dir + "/furnace.json"), 0);
  ASSERT_EQ(run("scene " + dir + "/furnace.json"), 0);
  ASSERT_EQ(run("bake " + dir + "/furnace.json --quiet -o " + dir + "/out"), 0);
  EXPECT_TRUE(std::filesystem::exists(dir + "/out/atlas.exr"));
}

TEST(Cli, RenderWritesReferenceImage) {
  std::string dir = tempDir("render");
  std::filesystem::create_directories(dir);
  ASSERT_EQ(run("render --scene chess --camera 1 --spp 2 --width 64 --height 36 --quiet -o " + dir +
                "/ref.exr"),
            0);
  auto image = readExr(dir + "/ref.exr", kRgbChannels);
  ASSERT_TRUE(image.ok());
  double sum = 0.0;
  for (float v : image->pixels) sum += v;
  EXPECT_GT(sum, 0.0);
  EXPECT_EQ(run("render --scene chess --camera 9 --quiet -o " + dir + "/bad.exr"), 1);
}

}  // namespace
}  // namespace rdm

namespace rdm {
namespace {

const std::string kTiny = " --spp 1 --max-hemisphere 4 ";

TEST(CliHelp, HelpGoesToStdoutWithEveryFlagAndItsDefault) {
  CliResult r = runRdm("bake --help");
  EXPECT_EQ(r.code, 0);
  EXPECT_TRUE(r.err.empty()) << r.err;
  for (const char* flag : {"--max-spp-factor", "--target-error", "--threads", "--shard",
                           "--backend", "--spp", "--max-hemisphere", "--quiet", "--output"})
    EXPECT_TRUE(contains(r.out, flag)) << flag;
  EXPECT_TRUE(contains(r.out, "--max-spp-factor INT:POSITIVE=16")) << r.out;
  EXPECT_TRUE(contains(runRdm("render --help").out, "--width INT:POSITIVE=1280"));
  EXPECT_TRUE(contains(runRdm("--help").out, "cancel"));
  CliResult unknown = runRdm("bake --scene chess --frobnicate -o x");
  EXPECT_EQ(unknown.code, 2);
  EXPECT_TRUE(contains(unknown.err, "unknown option --frobnicate")) << unknown.err;
}

TEST(CliHelp, VersionNamesTheBuild) {
  CliResult r = runRdm("--version");
  EXPECT_EQ(r.code, 0);
  EXPECT_EQ(r.out.rfind("rdm rdm-cpu ", 0), 0u) << r.out;
}

TEST(CliErrors, MistypedSceneListsTheBuiltInScenes) {
  CliResult r = runRdm("bake --scene chesss -o " + tempDir("typo"));
  EXPECT_EQ(r.code, 1);
  for (const char* part : {"neither a built-in scene", "chess, island, furnace",
                           "nor a readable scene file", "Did you mean 'chess'"})
    EXPECT_TRUE(contains(r.err, part)) << r.err;
}

TEST(CliErrors, ImpossibleOutputFailsBeforeTheBake) {
  for (const std::string verb : {"bake --scene chess", "render --scene chess --spp 1"}) {
    const std::string out = verb[0] == 'b' ? "/dev/null/out" : "/dev/null/out.exr";
    CliResult r = runRdm(verb + " -o " + out);
    EXPECT_EQ(r.code, 1) << verb;
    EXPECT_TRUE(contains(r.err, out)) << r.err;
    EXPECT_FALSE(contains(r.err, "progress")) << "the bake started: " << r.err;
    EXPECT_FALSE(contains(r.out, "RDMs:")) << r.out;
  }
  CliResult missing = runRdm("render --scene chess -o " + tempDir("none") + "/sub/ref.exr");
  EXPECT_EQ(missing.code, 1);
  EXPECT_TRUE(contains(missing.err, "does not exist")) << missing.err;
}

TEST(CliErrors, MessagesNameTheUsersFileNotTempFiles) {
  std::string dir = tempDir("tmpnames");
  std::filesystem::create_directories(dir);
  ASSERT_EQ(
      runRdm("render --scene chess --spp 1 --width 16 --height 9 -q -o " + dir + "/a.exr").code, 0);
  CliResult r = runRdm("flip " + dir + "/a.exr " + dir + "/a.exr --map " + dir + "/no/map.png");
  EXPECT_EQ(r.code, 1);
  EXPECT_TRUE(contains(r.err, dir + "/no/map.png")) << r.err;
  EXPECT_FALSE(contains(r.err, ".tmp")) << r.err;
}

TEST(CliErrors, NetworkErrorsNameTheServerAndTheCause) {
  CliResult r = runRdm("status j_0123456789abcdef --server http://127.0.0.1:1");
  EXPECT_EQ(r.code, 1);
  EXPECT_TRUE(contains(r.err, "http://127.0.0.1:1")) << r.err;
  EXPECT_TRUE(contains(r.err, "Connection refused")) << r.err;
}

TEST(CliRender, FormatFollowsTheExtension) {
  std::string dir = tempDir("formats");
  std::filesystem::create_directories(dir);
  const std::string render = "render --scene chess --spp 1 --width 16 --height 9 -q -o " + dir;
  ASSERT_EQ(runRdm(render + "/x.png").code, 0);
  auto png = readFileToString(dir + "/x.png");
  ASSERT_TRUE(png.ok());
  EXPECT_EQ(png->substr(1, 3), "PNG");
  ASSERT_EQ(runRdm(render + "/x.exr").code, 0);
  EXPECT_TRUE(readExr(dir + "/x.exr", kRgbChannels).ok());
  CliResult jpg = runRdm(render + "/x.jpg");
  EXPECT_EQ(jpg.code, 2);
  EXPECT_TRUE(contains(jpg.err, "unknown image format")) << jpg.err;
  EXPECT_FALSE(std::filesystem::exists(dir + "/x.jpg"));
}

TEST(CliPreview, DepthAndNoiseOfABakedAtlas) {
  std::string dir = tempDir("preview");
  ASSERT_EQ(runRdm("bake --scene chess" + kTiny + "-q -o " + dir).code, 0);
  CliResult depth = runRdm("preview " + dir + "/atlas.exr --depth -o " + dir + "/depth.png");
  EXPECT_EQ(depth.code, 0) << depth.err;
  EXPECT_TRUE(std::filesystem::file_size(dir + "/depth.png") > 100);
  auto noise = readExr(dir + "/noise.exr", {"E"});
  ASSERT_TRUE(noise.ok()) << noise.error();
  float largest = 0.0f;
  for (float v : noise->pixels) largest = std::max(largest, v);
  EXPECT_GT(largest, 0.0f);  // 1 spp leaves noise
  CliResult map = runRdm("preview " + dir + " --noise -o " + dir + "/noise.png");
  EXPECT_EQ(map.code, 0) << map.err;
  EXPECT_TRUE(std::filesystem::exists(dir + "/noise.png"));
  ASSERT_EQ(
      runRdm("render --scene chess --spp 1 --width 16 --height 9 -q -o " + dir + "/r.exr").code, 0);
  CliResult refused = runRdm("preview " + dir + "/r.exr --noise -o " + dir + "/rn.png");
  EXPECT_EQ(refused.code, 1);
  EXPECT_TRUE(contains(refused.err, "standard errors")) << refused.err;
  CliResult render_depth = runRdm("preview " + dir + "/r.exr --depth -o " + dir + "/rd.png");
  EXPECT_EQ(render_depth.code, 1);
  EXPECT_TRUE(contains(render_depth.err, "no channel 'Z'")) << render_depth.err;
}

TEST(CliBake, SummarySaysUsefulTexelsAndWhatIsNotPresent) {
  std::string dir = tempDir("summary");
  CliResult r = runRdm("bake --scene chess" + kTiny + "-q -o " + dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(contains(r.out, "useful texels fill")) << r.out;
  EXPECT_TRUE(contains(r.out, "not present:")) << r.out;
  EXPECT_FALSE(contains(r.out, "skipped:   roughness")) << r.out;
  auto report = readFileToString(dir + "/bake_report.json");
  ASSERT_TRUE(report.ok());
  auto j = nlohmann::json::parse(*report);
  // Skipped faces take no atlas space (index version 2), so the pages are nearly all useful.
  EXPECT_GE(j["occupancy"].get<double>(), 0.95);
  EXPECT_LT(j["useful_texels"].get<uint64_t>(), j["texels"].get<uint64_t>());
  CliResult target = runRdm("bake --scene chess" + kTiny + "--target-error 0.5 -q -o " + dir);
  ASSERT_EQ(target.code, 0) << target.err;
  EXPECT_TRUE(contains(target.out, "target 50.00 %")) << target.out;
  EXPECT_FALSE(contains(target.out, "at 1 spp")) << target.out;
}

// The bake states its estimate first and refuses, before any work and writing nothing, when
// the estimated peak memory exceeds --max-memory; the message names both and what to change.
TEST(CliBake, EstimateIsPrintedAndAnOversizedBakeIsRefusedBeforeWork) {
  const std::string dir = tempDir("estimate");
  CliResult ok = runRdm("bake --scene chess" + kTiny + "-o " + dir);
  ASSERT_EQ(ok.code, 0) << ok.err;
  EXPECT_TRUE(contains(ok.out, "estimate:    162 RDMs of 80 blocks")) << ok.out;
  auto report = nlohmann::json::parse(*readFileToString(dir + "/bake_report.json"));
  EXPECT_LE(report["peak_rdms_held"].get<int>(), 2 * 8);  // threads x levels: streamed
  const std::string refused_dir = tempDir("estimate_refused");
  CliResult refused = runRdm("bake --scene chess" + kTiny + "--max-memory 1000 -o " + refused_dir);
  EXPECT_EQ(refused.code, 1);
  EXPECT_TRUE(contains(refused.err, "more than --max-memory (1.00 kB)")) << refused.err;
  EXPECT_TRUE(contains(refused.err, "--max-hemisphere")) << refused.err;
  EXPECT_TRUE(contains(refused.err, "--shard")) << refused.err;
  EXPECT_FALSE(contains(refused.out, "RDMs:")) << refused.out;  // no bake ran
  EXPECT_FALSE(std::filesystem::exists(refused_dir));
}

// --radiance half writes R, G, B at 16 bits (docs/spec.md section 4): the report and the index
// say so, the pages are smaller, and an unknown format is refused by name.
TEST(CliBake, HalfRadianceIsReportedIndexedAndSmaller) {
  const std::string full = tempDir("radiance_float"), half = tempDir("radiance_half");
  ASSERT_EQ(runRdm("bake --scene island" + kTiny + "-q -o " + full).code, 0);
  CliResult r = runRdm("bake --scene island" + kTiny + "--radiance half -q -o " + half);
  ASSERT_EQ(r.code, 0) << r.err;
  auto report = nlohmann::json::parse(*readFileToString(half + "/bake_report.json"));
  EXPECT_EQ(report["radiance"], "half");
  auto index = nlohmann::json::parse(*readFileToString(half + "/index.json"));
  EXPECT_EQ(index["radiance"], "half");
  EXPECT_LT(std::filesystem::file_size(half + "/atlas.exr"),
            std::filesystem::file_size(full + "/atlas.exr"));
  CliResult bad = runRdm("bake --scene island" + kTiny + "--radiance bf16 -q -o " + half);
  EXPECT_NE(bad.code, 0);
  EXPECT_TRUE(contains(bad.err, "--radiance")) << bad.err;
}

TEST(CliBake, FaceLightIsWrittenReportedAndReadBack) {
  const std::string dir = tempDir("face_light");
  CliResult r = runRdm("bake --scene chess" + kTiny + "--face-light 2 -q -o " + dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(contains(r.out, "face light:")) << r.out;
  auto report = nlohmann::json::parse(*readFileToString(dir + "/bake_report.json"));
  EXPECT_EQ(report["face_light"]["spp"], 2);
  auto light = readFaceLight(dir + "/face_light.bin");
  ASSERT_TRUE(light.ok()) << light.error();
  EXPECT_EQ(light->faceCount(), report["face_light"]["faces"].get<size_t>());
  EXPECT_GT(light->faceCount(), 40000u);  // chess: 47,568 exposed voxel faces
}

// Without --face-light the bake takes the scene's bake.face_light_spp (the furnace's 64);
// --face-light 0 bakes none.
TEST(CliBake, FaceLightFollowsTheSceneUnlessTheOptionSaysOtherwise) {
  const std::string by_scene = tempDir("face_light_scene"), none = tempDir("face_light_none");
  ASSERT_EQ(builtinScene("furnace")->face_light_spp, 64);
  CliResult r = runRdm("bake --scene furnace" + kTiny + "-q -o " + by_scene);
  ASSERT_EQ(r.code, 0) << r.err;
  auto light = readFaceLight(by_scene + "/face_light.bin");
  ASSERT_TRUE(light.ok()) << light.error();
  EXPECT_EQ(light->spp, 64u);
  r = runRdm("bake --scene furnace" + kTiny + "--face-light 0 -q -o " + none);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_FALSE(std::filesystem::exists(none + "/face_light.bin"));
  auto report = nlohmann::json::parse(*readFileToString(none + "/bake_report.json"));
  EXPECT_FALSE(report.contains("face_light"));
}

TEST(CliBake, QualityPresetPredictsBeforeTheBakeAndReportsBoth) {
  std::string dir = tempDir("quality");
  CliResult r =
      runRdm("bake --scene island --quality draft --predict --max-hemisphere 8 -o " + dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const size_t predicted = r.out.find("predicted:"), progress = r.out.find("progress:");
  ASSERT_NE(predicted, std::string::npos) << r.out;
  EXPECT_TRUE(progress == std::string::npos || predicted < progress) << r.out;
  EXPECT_TRUE(contains(r.out, "quality draft, 4 spp")) << r.out;
  EXPECT_TRUE(contains(r.out, "measured")) << r.out;
  auto report = readFileToString(dir + "/bake_report.json");
  ASSERT_TRUE(report.ok());
  auto j = nlohmann::json::parse(*report);
  EXPECT_EQ(j["quality"], "draft");
  EXPECT_EQ(j["spp"], 4);
  EXPECT_EQ(j["max_bounces"], 2);
  EXPECT_EQ(j["estimator"], "prefiltered");
  EXPECT_GT(j["predicted"]["seconds"].get<double>(), 0.0);
  EXPECT_GT(j["predicted"]["mean_relative_error"].get<double>(), 0.0);
  // CPU time is summed over the bake's threads: on a machine with more than one core it may
  // exceed the wall time, and it is never zero for a bake that traced rays.
  EXPECT_GT(j["predicted"]["cpu_seconds"].get<double>(), 0.0);
  EXPECT_GT(j["cpu_seconds"].get<double>(), 0.0);
  EXPECT_LT(j["cpu_seconds"].get<double>(),
            (j["threads"].get<double>() + 0.5) * j["seconds"].get<double>() + 0.01);
  // An explicit --spp wins over the preset's.
  CliResult spp =
      runRdm("bake --scene island --quality final --spp 2 --max-hemisphere 4 -q -o " + dir);
  ASSERT_EQ(spp.code, 0) << spp.err;
  report = readFileToString(dir + "/bake_report.json");
  ASSERT_TRUE(report.ok());
  EXPECT_EQ(nlohmann::json::parse(*report)["spp"], 2);
  CliResult bad = runRdm("bake --scene island --quality best -o " + dir);
  EXPECT_EQ(bad.code, 2);
  EXPECT_TRUE(contains(bad.err, "--quality")) << bad.err;
}

TEST(CliBake, EstimatorIsASettingOfTheBake) {
  std::string dir = tempDir("estimator");
  CliResult r = runRdm("bake --scene chess" + kTiny + "--estimator naive -q -o " + dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(contains(r.out, "naive estimator")) << r.out;
  auto report = readFileToString(dir + "/bake_report.json");
  ASSERT_TRUE(report.ok());
  EXPECT_EQ(nlohmann::json::parse(*report)["estimator"], "naive");
  CliResult bad = runRdm("bake --scene chess" + kTiny + "--estimator fancy -q -o " + dir);
  EXPECT_EQ(bad.code, 2);
  EXPECT_TRUE(contains(bad.err, "--estimator")) << bad.err;
  // The Vulkan backend bakes the default (prefiltered) estimator too.
  CliResult vk = runRdm("bake --scene chess" + kTiny + "--backend vulkan -q -o " + dir);
  ASSERT_EQ(vk.code, 0) << vk.err;
  auto vk_report = readFileToString(dir + "/bake_report.json");
  ASSERT_TRUE(vk_report.ok());
  EXPECT_EQ(nlohmann::json::parse(*vk_report)["backend"], "vulkan");
  EXPECT_EQ(nlohmann::json::parse(*vk_report)["estimator"], "prefiltered");
  // rdms.bin carries the device's slot sets (a baked face's first segments start in the
  // neighbour slot; RDMs with every face skipped have none).
  auto records = readSlotSetsFile(dir);
  ASSERT_TRUE(records.ok()) << records.error();
  size_t with_sets = 0;
  for (const auto& [key, record] : *records) with_sets += record.first_set.empty() ? 0 : 1;
  EXPECT_GT(with_sets, records->size() / 2);
}

TEST(CliBake, NoEtaBeforeItMeansSomething) {
  CliResult r = runRdm("bake --scene chess" + kTiny + "-o " + tempDir("eta"));
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string first = r.err.substr(0, r.err.find('\n'));
  EXPECT_TRUE(contains(first, "progress: 0.0%")) << first;
  EXPECT_TRUE(contains(first, "ETA --")) << first;
  EXPECT_FALSE(contains(r.err, "ETA 0 s")) << r.err;
}

TEST(CliBake, CtrlCStopsBetweenUnitsAndWritesNothing) {
  const std::string dir = tempDir("cancel"), log = tempDir("cancel_log");
  // About 15 s of work on one thread; interrupted once the bake runs.
  pid_t pid = spawnRdm({"bake", "--scene", "island", "--spp", "256", "--max-hemisphere", "32",
                        "--threads", "1", "-o", dir},
                       log);
  ASSERT_GT(pid, 0);
  for (int i = 0; i < 200; ++i) {
    auto text = readFileToString(log);
    if (text.ok() && contains(*text, "progress:")) break;
    usleep(20000);
  }
  usleep(300000);
  kill(pid, SIGINT);
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status)) << "killed by signal " << WTERMSIG(status);
  EXPECT_EQ(WEXITSTATUS(status), 130);
  auto text = readFileToString(log);
  ASSERT_TRUE(text.ok());
  EXPECT_TRUE(contains(*text, "interrupted")) << *text;
  EXPECT_TRUE(contains(*text, "nothing was written")) << *text;
  EXPECT_FALSE(std::filesystem::exists(dir)) << "the bake created it, so it removes it empty";
}

}  // namespace
}  // namespace rdm

namespace rdm {
namespace {

std::string jobIdFrom(const std::string& submit_output) {
  const size_t at = submit_output.find("job ");
  if (at == std::string::npos) return {};
  return submit_output.substr(at + 4, submit_output.find('\n', at) - at - 4);
}

TEST(CliDaemon, StatusFetchCancelAndVersionAgainstARealDaemon) {
  const std::string dir = tempDir("daemon");
  std::filesystem::create_directories(dir);
  test::ServerProcess server(dir + "/data", {"--threads", "1"});
  ASSERT_GT(server.port(), 0);
  const std::string at = " --server " + server.url();
  CliResult submit = runRdm("submit furnace" + at);
  ASSERT_EQ(submit.code, 0) << submit.err;
  const std::string job = jobIdFrom(submit.out);
  ASSERT_FALSE(job.empty()) << submit.out;

  CliResult fetch = runRdm("fetch " + job + at + " -o " + dir + "/out");
  ASSERT_EQ(fetch.code, 0) << fetch.err;
  EXPECT_FALSE(contains(fetch.err, "ETA 0 s")) << fetch.err;
  auto report = readFileToString(dir + "/out/bake_report.json");
  ASSERT_TRUE(report.ok()) << "rdm fetch writes bake_report.json";
  EXPECT_EQ(nlohmann::json::parse(*report)["job"], job);
  // A bc6h job: submit asks for it, fetch downloads its atlas.ktx2 and depth.exr.
  CliResult bc6h_submit = runRdm("submit furnace --radiance bc6h" + at);
  ASSERT_EQ(bc6h_submit.code, 0) << bc6h_submit.err;
  CliResult bc6h_fetch =
      runRdm("fetch " + jobIdFrom(bc6h_submit.out) + at + " -o " + dir + "/bc6h");
  ASSERT_EQ(bc6h_fetch.code, 0) << bc6h_fetch.err;
  EXPECT_TRUE(contains(bc6h_fetch.out, "atlas.ktx2")) << bc6h_fetch.out;
  auto bc6h_atlas = readAtlasOutputs(dir + "/bc6h");
  ASSERT_TRUE(bc6h_atlas.ok()) << bc6h_atlas.error();
  EXPECT_EQ(bc6h_atlas->layout.radiance, RadianceFormat::kBc6h);

  CliResult human = runRdm("status " + job + at);
  ASSERT_EQ(human.code, 0) << human.err;
  for (const char* part :
       {"state:     succeeded", "pass:      full", "progress:  100.0 %", "re-baked"})
    EXPECT_TRUE(contains(human.out, part)) << human.out;
  CliResult raw = runRdm("status " + job + at + " --json");
  ASSERT_EQ(raw.code, 0) << raw.err;
  const auto status = nlohmann::json::parse(raw.out);
  CliResult version = runRdm("--version");
  EXPECT_EQ(version.out, "rdm " + status["build"].get<std::string>() + "\n");

  CliResult big = runRdm("submit chess" + at);
  ASSERT_EQ(big.code, 0) << big.err;
  const std::string long_job = jobIdFrom(big.out);
  CliResult cancel = runRdm("cancel " + long_job + at);
  EXPECT_EQ(cancel.code, 0) << cancel.err;
  EXPECT_TRUE(contains(cancel.out, "cancel requested")) << cancel.out;
  const auto after = nlohmann::json::parse(runRdm("status " + long_job + at + " --json").out);
  EXPECT_TRUE(after["cancel_requested"].get<bool>() || after["state"] == "cancelled") << after;
  CliResult missing = runRdm("cancel j_0000000000000000" + at);
  EXPECT_EQ(missing.code, 1);
  EXPECT_TRUE(contains(missing.err, server.url())) << missing.err;
}

}  // namespace
}  // namespace rdm
