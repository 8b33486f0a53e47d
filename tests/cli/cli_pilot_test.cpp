// The prediction pilot of `rdm bake --quality` is skipped when the bake is too cheap for it
// (docs/spec.md section 3.1, "Quality presets and prediction"), and runs otherwise.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "cli_run.h"
#include "rdm/bake/bake_prediction.h"

namespace rdm {
namespace {

// The rule's threshold sits between the estimates measured for chess draft (2.6 CPU-s, a
// pilot of 26 % of the bake) and chess preview (16.2 CPU-s, 9 %).
TEST(CliPilot, RuleSkipsBelowTheThresholdOnly) {
  EXPECT_DOUBLE_EQ(kSkipPilotBelowEstimatedCpuSeconds,
                   kMinPilotCpuSeconds / kMaxPilotShare * kEstimateOverstatement);
  EXPECT_FALSE(pilotWorthRunning(2.6));
  EXPECT_FALSE(pilotWorthRunning(0.0));
  EXPECT_TRUE(pilotWorthRunning(16.2));
  EXPECT_TRUE(pilotWorthRunning(kSkipPilotBelowEstimatedCpuSeconds));
}

nlohmann::json bakeReport(const std::string& dir) {
  auto text = readFileToString(dir + "/bake_report.json");
  EXPECT_TRUE(text.ok()) << dir;
  return text.ok() ? nlohmann::json::parse(*text) : nlohmann::json::object();
}

TEST(CliPilot, DraftChessSkipsThePilotAndSaysSo) {
  const std::string dir = tempDir("pilot_draft");
  CliResult r = runRdm("bake --scene chess --quality draft --face-light 0 -o " + dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(contains(r.out, "prediction:  skipped, the bake is too cheap for its pilot"))
      << r.out;
  EXPECT_FALSE(contains(r.out, "pilot:")) << r.out;
  EXPECT_FALSE(contains(r.out, "predicted:")) << r.out;
  const nlohmann::json j = bakeReport(dir);
  EXPECT_FALSE(j.contains("predicted")) << j.dump();
  EXPECT_EQ(j["spp"], 4);  // the preset still applies
  EXPECT_EQ(j.value("quality", ""), "draft");
}

TEST(CliPilot, LargerBakeRunsThePilot) {
  const std::string dir = tempDir("pilot_preview");
  CliResult r = runRdm("bake --scene island --quality preview --face-light 0 -o " + dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_FALSE(contains(r.out, "prediction:  skipped")) << r.out;
  EXPECT_TRUE(contains(r.out, "pilot:")) << r.out;
  const nlohmann::json j = bakeReport(dir);
  ASSERT_TRUE(j.contains("predicted")) << j.dump();
  EXPECT_GT(j["predicted"]["pilot_slots"].get<int>(), 0);
}

TEST(CliPilot, PredictRunsThePilotOfACheapBake) {
  const std::string dir = tempDir("pilot_forced");
  CliResult r = runRdm("bake --scene chess --quality draft --predict --face-light 0 -o " + dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_FALSE(contains(r.out, "prediction:  skipped")) << r.out;
  EXPECT_TRUE(contains(r.out, "pilot:")) << r.out;
  EXPECT_TRUE(bakeReport(dir).contains("predicted"));
}

}  // namespace
}  // namespace rdm
