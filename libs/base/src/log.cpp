#include "rdm/base/log.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>

namespace rdm {
namespace {

std::atomic<int> g_level{int(LogLevel::kInfo)};

constexpr const char* kNames[] = {"debug", "info", "warn", "error", "off"};

std::string isoTime(double unix_seconds) {
  const double whole = std::floor(unix_seconds);
  const time_t t = time_t(whole);
  tm utc{};
  gmtime_r(&t, &utc);
  char text[40];
  const int ms = std::min(999, int((unix_seconds - whole) * 1000.0));
  std::snprintf(text, sizeof text, "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ", utc.tm_year + 1900,
                utc.tm_mon + 1, utc.tm_mday, utc.tm_hour, utc.tm_min, utc.tm_sec, ms);
  return text;
}

}  // namespace

void setLogLevel(LogLevel level) {
  g_level = int(level);
}

bool logEnabled(LogLevel level) {
  return level != LogLevel::kOff && int(level) >= g_level.load(std::memory_order_relaxed);
}

bool parseLogLevel(std::string_view text, LogLevel& level) {
  for (int i = 0; i <= int(LogLevel::kOff); ++i) {
    if (text == kNames[i]) {
      level = LogLevel(i);
      return true;
    }
  }
  return false;
}

const char* logLevelName(LogLevel level) {
  return kNames[int(level)];
}

std::string formatLogLine(double unix_seconds, LogLevel level, std::string_view event,
                          const nlohmann::ordered_json& fields) {
  nlohmann::ordered_json line;
  line["ts"] = isoTime(unix_seconds);
  line["level"] = logLevelName(level);
  line["event"] = std::string(event);
  if (fields.is_object()) {
    for (const auto& [key, value] : fields.items()) line[key] = value;
  }
  // Invalid UTF-8 in a field (a client's path) is replaced, never thrown on.
  return line.dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace);
}

void logEvent(LogLevel level, std::string_view event, const nlohmann::ordered_json& fields) {
  if (!logEnabled(level)) return;
  const double now =
      std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
  const std::string line = formatLogLine(now, level, event, fields) + "\n";
  // One write per line: lines of concurrent threads never interleave (stderr is unbuffered).
  size_t off = 0;
  while (off < line.size()) {
    const ssize_t n = ::write(STDERR_FILENO, line.data() + off, line.size() - off);
    if (n <= 0) return;
    off += size_t(n);
  }
}

}  // namespace rdm
