// posebench's log (spdlog, on stderr): one line per event,
//   2026-11-23T20:10:00.123 info trial key=/1/0/cvfh/icp/n0 status=ok correct=true total_s=0.12
// the event's fields named as in the records (eval/record.h) where they are
// record fields. Levels: -q shows warnings and errors, the default adds
// info (what a run does), -v adds debug (one line per finished trial).
// Progress bars on a terminal are not log lines; errors that end a command
// (exit 2) are its one message, not log lines.
#pragma once

#include <nlohmann/json.hpp>

#include <string>

namespace pb {

enum class LogLevel { debug, info, warn, error };

void set_log_level(LogLevel level);
LogLevel log_level();
bool log_enabled(LogLevel level);

// One line: EVENT then key=value per field of `fields` (a JSON object, in
// its order): strings as they are unless they hold spaces, quotes or '='
// (then JSON-quoted), other values as JSON.
void log_event(LogLevel level, const std::string& event, const nlohmann::ordered_json& fields = {});

// The line log_event writes after the time and level (for tests).
std::string format_log_event(const std::string& event, const nlohmann::ordered_json& fields);

}  // namespace pb
