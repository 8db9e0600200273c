#include "log.h"

#include <unistd.h>

#include <ctime>

namespace tumble::server {
namespace {

std::atomic<int> enabled_level{static_cast<int>(LogLevel::kInfo)};

constexpr const char* kNames[] = {"error", "warn", "info", "debug"};

}  // namespace

std::optional<LogLevel> log_level_from_name(std::string_view name) {
  for (int level = 0; level < 4; ++level)
    if (name == kNames[level]) return static_cast<LogLevel>(level);
  return std::nullopt;
}

void set_log_level(LogLevel level) {
  enabled_level = static_cast<int>(level);
}

bool logs(LogLevel level) {
  return static_cast<int>(level) <= enabled_level;
}

void log(LogLevel level, const std::string& message) {
  if (!logs(level)) return;
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y-%m-%dT%H:%M:%SZ", &utc);
  std::string line = stamp;
  line += ' ';
  line += kNames[static_cast<int>(level)];
  line.append(6 - std::char_traits<char>::length(kNames[static_cast<int>(level)]), ' ');
  line += message;
  line += '\n';
  // One write(2) per line, so lines from several threads never interleave.
  const ssize_t written = ::write(STDERR_FILENO, line.data(), line.size());
  (void)written;
}

}  // namespace tumble::server
