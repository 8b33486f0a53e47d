// Structured logs: one JSON object per line on stderr, the format journald and Kubernetes
// collect as is (docs/api.md, "Logs"). Every line has `ts` (UTC, ISO 8601 with milliseconds),
// `level` and `event`; the caller adds its fields. Thread-safe: a line is one write(2).
#pragma once

#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

namespace rdm {

enum class LogLevel { kDebug = 0, kInfo = 1, kWarn = 2, kError = 3, kOff = 4 };

// Lines below `level` are dropped (default kInfo).
void setLogLevel(LogLevel level);
bool logEnabled(LogLevel level);
// "debug", "info", "warn", "error" or "off"; false for anything else.
[[nodiscard]] bool parseLogLevel(std::string_view text, LogLevel& level);
const char* logLevelName(LogLevel level);

// Writes {"ts":..., "level":..., "event": event, ...fields} when `level` is enabled.
// `fields` must be a JSON object (or null); its keys keep their order.
void logEvent(LogLevel level, std::string_view event, const nlohmann::ordered_json& fields = {});

// The line logEvent writes, without the newline, for a given time (seconds since the epoch).
std::string formatLogLine(double unix_seconds, LogLevel level, std::string_view event,
                          const nlohmann::ordered_json& fields);

}  // namespace rdm
