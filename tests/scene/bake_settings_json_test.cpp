// The one bake-settings codec (rdm/scene/bake_settings_json.h): its JSON forms round trip, and
// every edge of its range table is accepted inside and refused outside, by the JSON reader and by
// the in-memory validator alike, with the field and the allowed range named.
#include "rdm/scene/bake_settings_json.h"

#include <gtest/gtest.h>

#include <string>

#include <nlohmann/json.hpp>

namespace rdm {
namespace {

using nlohmann::json;

BakeSettings sampleSettings() {
  return {17, 3, 4000000000u, 64, Estimator::kNaive};
}

Expected<BakeSettings> readInput(const json& j, const std::string& path = "bake") {
  return readBakeSettings(j, {path, BakeSettings{}, BakeSettingsForm::kInput, {}});
}

void expectRefused(const Status& s, const std::string& field, const std::string& needle) {
  ASSERT_FALSE(s.ok()) << field;
  EXPECT_EQ(s.code(), StatusCode::kInvalidInput) << s.message();
  EXPECT_EQ(s.field(), field) << s.message();
  EXPECT_NE(s.message().find("'" + field + "'"), std::string::npos) << s.message();
  EXPECT_NE(s.message().find(needle), std::string::npos) << s.message();
}

TEST(BakeSettingsJson, RoundTripsEveryForm) {
  const BakeSettings s = sampleSettings();
  const json j = bakeSettingsToJson(s);
  EXPECT_EQ(j.dump(),
            R"({"estimator":"naive","max_bounces":3,"max_hemisphere":64,"seed":4000000000,)"
            R"("spp":17})");
  for (BakeSettingsForm form :
       {BakeSettingsForm::kInput, BakeSettingsForm::kRecord, BakeSettingsForm::kLegacyRecord}) {
    auto back = readBakeSettings(j, {"settings", {}, form, {}});
    ASSERT_TRUE(back.ok()) << back.error();
    EXPECT_EQ(*back, s);
  }
  EXPECT_TRUE(validateBakeSettings(s).ok());
  EXPECT_TRUE(validateBakeSettings(BakeSettings{}).ok());
}

TEST(BakeSettingsJson, ReportFormLeavesOutTheSeed) {
  const json j = bakeSettingsToJson(sampleSettings(), BakeSettingsKeys::kReport);
  EXPECT_EQ(j.dump(), R"({"estimator":"naive","max_bounces":3,"max_hemisphere":64,"spp":17})");
}

TEST(BakeSettingsJson, InputKeepsDefaultsAndRefusesUnknownKeys) {
  BakeSettings defaults = sampleSettings();
  auto s = readBakeSettings(json{{"spp", 5}, {"quality", "draft"}},
                            {"settings", defaults, BakeSettingsForm::kInput, {"quality"}});
  ASSERT_TRUE(s.ok()) << s.error();
  defaults.spp = 5;
  EXPECT_EQ(*s, defaults);
  expectRefused(readInput(json{{"bogus", 1}}).status(), "bake.bogus", "unknown key");
  expectRefused(readInput(json::array()).status(), "bake", "expected an object");
  expectRefused(readInput(json{{"spp", 1.5}}).status(), "bake.spp", "expected an integer");
}

TEST(BakeSettingsJson, RecordsRequireEveryKeyButLegacyOnes) {
  json j = bakeSettingsToJson(sampleSettings());
  j["later_version_key"] = 1;  // records ignore keys they do not know
  j.erase("estimator");
  auto legacy = readBakeSettings(j, {"settings", {}, BakeSettingsForm::kLegacyRecord, {}});
  ASSERT_TRUE(legacy.ok()) << legacy.error();
  EXPECT_EQ(legacy->estimator, Estimator::kNaive);
  expectRefused(readBakeSettings(j, {"settings", {}, BakeSettingsForm::kRecord, {}}).status(),
                "settings.estimator", "required");
  j.erase("spp");
  expectRefused(readBakeSettings(j, {"settings", {}, BakeSettingsForm::kLegacyRecord, {}}).status(),
                "settings.spp", "required");
}

TEST(BakeSettingsJson, EveryRangeEdgeIsAcceptedInsideAndRefusedOutside) {
  const auto ranges = bakeSettingRanges();
  ASSERT_EQ(ranges.size(), 4u);
  for (const BakeSettingRange& r : ranges) {
    SCOPED_TRACE(r.key);
    const std::string allowed = "[" + std::to_string(r.lo) + ", " + std::to_string(r.hi) + "]";
    for (long long v : {r.lo, r.hi}) {
      auto in = readInput(json{{r.key, v}});
      ASSERT_TRUE(in.ok()) << in.error();
      EXPECT_EQ(bakeSettingsToJson(*in)[r.key], v);
      EXPECT_TRUE(validateBakeSettings(*in).ok());
    }
    for (long long v : {r.lo - 1, r.hi + 1}) {
      expectRefused(readInput(json{{r.key, v}}).status(), "bake." + r.key, allowed);
      expectRefused(readInput(json{{r.key, v}}, "settings").status(), "settings." + r.key, allowed);
    }
    if (r.power_of_two) {
      expectRefused(readInput(json{{r.key, r.lo + 1}}).status(), "bake." + r.key, "power of two");
      EXPECT_TRUE(readInput(json{{r.key, r.lo * 2}}).ok());
    }
  }
  // Values past the field types: seed 2^32 and 2^64 - 1 are out of range, not wrapped.
  expectRefused(readInput(json{{"seed", 4294967296LL}}).status(), "bake.seed", "[0, 4294967295]");
  expectRefused(readInput(json{{"seed", 18446744073709551615ULL}}).status(), "bake.seed",
                "[0, 4294967295]");
}

TEST(BakeSettingsJson, ValidatorNamesFieldAndRange) {
  BakeSettings s;
  s.spp = 0;
  expectRefused(validateBakeSettings(s), "bake.spp", "[1, 65536]");
  s = {};
  s.spp = 65537;
  expectRefused(validateBakeSettings(s, "settings"), "settings.spp", "[1, 65536]");
  s = {};
  s.max_bounces = -1;
  expectRefused(validateBakeSettings(s), "bake.max_bounces", "[0, 64]");
  s = {};
  s.max_bounces = 65;
  expectRefused(validateBakeSettings(s), "bake.max_bounces", "[0, 64]");
  for (int hemi : {1, 3, 96, 512}) {
    s = {};
    s.max_hemisphere = hemi;
    expectRefused(validateBakeSettings(s), "bake.max_hemisphere", "power of two in [2, 256]");
  }
}

TEST(BakeSettingsJson, UnknownEstimatorNamesTheReason) {
  auto e = parseEstimator("magic");
  ASSERT_FALSE(e.ok());
  EXPECT_NE(e.error().find("unknown estimator \"magic\""), std::string::npos) << e.error();
  EXPECT_NE(e.error().find("\"naive\" or \"prefiltered\""), std::string::npos) << e.error();
  expectRefused(readInput(json{{"estimator", "magic"}}).status(), "bake.estimator",
                "unknown estimator \"magic\"");
  expectRefused(readInput(json{{"estimator", 1}}).status(), "bake.estimator",
                "\"naive\" or \"prefiltered\"");
  for (Estimator known : {Estimator::kNaive, Estimator::kPrefiltered}) {
    auto parsed = parseEstimator(estimatorName(known));
    ASSERT_TRUE(parsed.ok());
    EXPECT_EQ(*parsed, known);
  }
}

TEST(BakeSettingsJson, FaceLightSppRange) {
  EXPECT_TRUE(checkFaceLightSpp(0).ok());
  EXPECT_TRUE(checkFaceLightSpp(65536).ok());
  expectRefused(checkFaceLightSpp(-1), "bake.face_light_spp", "[0, 65536]");
  expectRefused(checkFaceLightSpp(65537), "bake.face_light_spp", "[0, 65536]");
  auto read = readFaceLightSpp(json(7), "bake.face_light_spp");
  ASSERT_TRUE(read.ok());
  EXPECT_EQ(*read, 7);
  expectRefused(readFaceLightSpp(json("7"), "bake.face_light_spp").status(), "bake.face_light_spp",
                "expected an integer");
}

}  // namespace
}  // namespace rdm
