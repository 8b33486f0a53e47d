#include "rdm/base/log.h"

#include <gtest/gtest.h>

namespace rdm {
namespace {

TEST(Log, LineIsOneJsonObjectWithTimeLevelEventAndFields) {
  // 2026-12-06T05:00:00.250Z
  const std::string line = formatLogLine(1796533200.25, LogLevel::kWarn, "request",
                                         {{"status", 404}, {"route", "/v1/jobs/{id}"}});
  EXPECT_EQ(line.find('\n'), std::string::npos);
  const auto j = nlohmann::json::parse(line);
  EXPECT_EQ(j["ts"], "2026-12-06T05:00:00.250Z");
  EXPECT_EQ(j["level"], "warn");
  EXPECT_EQ(j["event"], "request");
  EXPECT_EQ(j["status"], 404);
  EXPECT_EQ(j["route"], "/v1/jobs/{id}");
  EXPECT_EQ(line.rfind("{\"ts\":", 0), 0u);  // fixed leading keys, for grep and humans
}

TEST(Log, InvalidUtf8InAFieldIsReplacedNotThrown) {
  const std::string bad = std::string("/v1/") + char(0xff) + "x";
  std::string line;
  ASSERT_NO_THROW(line = formatLogLine(0.0, LogLevel::kInfo, "request", {{"path", bad}}));
  EXPECT_TRUE(nlohmann::json::accept(line));
}

TEST(Log, LevelsParseAndFilter) {
  LogLevel level{};
  EXPECT_TRUE(parseLogLevel("debug", level));
  EXPECT_EQ(level, LogLevel::kDebug);
  EXPECT_TRUE(parseLogLevel("off", level));
  EXPECT_FALSE(parseLogLevel("verbose", level));
  setLogLevel(LogLevel::kWarn);
  EXPECT_FALSE(logEnabled(LogLevel::kInfo));
  EXPECT_TRUE(logEnabled(LogLevel::kError));
  EXPECT_FALSE(logEnabled(LogLevel::kOff));
  setLogLevel(LogLevel::kInfo);
  EXPECT_TRUE(logEnabled(LogLevel::kInfo));
}

}  // namespace
}  // namespace rdm
