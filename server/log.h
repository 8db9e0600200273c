// The server's log: one line per event on stderr, "2026-11-26T20:31:07Z warn  the world fell
// behind ...", filtered by a level that --log-level sets. Errors and warnings are what an operator
// must read; info (the default) adds what the server did (started, loaded, restored, stopped);
// debug adds every refused request and every subscriber that came or went.
#pragma once

#include <atomic>
#include <optional>
#include <string>
#include <string_view>

namespace tumble::server {

enum class LogLevel { kError = 0, kWarn = 1, kInfo = 2, kDebug = 3 };

std::optional<LogLevel> log_level_from_name(std::string_view name);  // error, warn, info, debug
void set_log_level(LogLevel level);
bool logs(LogLevel level);

// Writes one line when `level` is enabled; safe from any thread (one write per line).
void log(LogLevel level, const std::string& message);

}  // namespace tumble::server
