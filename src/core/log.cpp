#include "core/log.h"

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <atomic>

namespace pb {

namespace {

std::atomic<LogLevel> g_level{LogLevel::info};

spdlog::logger& logger() {
  static std::shared_ptr<spdlog::logger> l = [] {
    auto lg = spdlog::stderr_color_st("posebench");
    lg->set_pattern("%Y-%m-%dT%H:%M:%S.%e %^%l%$ %v");
    lg->set_level(spdlog::level::trace);  // filtered by g_level
    lg->flush_on(spdlog::level::trace);   // a killed run loses no line
    return lg;
  }();
  return *l;
}

spdlog::level::level_enum to_spdlog(LogLevel l) {
  switch (l) {
    case LogLevel::debug: return spdlog::level::debug;
    case LogLevel::info: return spdlog::level::info;
    case LogLevel::warn: return spdlog::level::warn;
    default: return spdlog::level::err;
  }
}

}  // namespace

void set_log_level(LogLevel level) { g_level = level; }
LogLevel log_level() { return g_level; }
bool log_enabled(LogLevel level) { return static_cast<int>(level) >= static_cast<int>(g_level.load()); }

std::string format_log_event(const std::string& event, const nlohmann::ordered_json& fields) {
  std::string line = event;
  if (!fields.is_object()) return line;
  for (const auto& [k, v] : fields.items()) {
    line += " " + k + "=";
    if (v.is_string()) {
      const std::string& s = v.get_ref<const std::string&>();
      const bool plain = !s.empty() && s.find_first_of(" \t\n\"'=") == std::string::npos;
      line += plain ? s : v.dump();
    } else {
      line += v.dump();
    }
  }
  return line;
}

void log_event(LogLevel level, const std::string& event, const nlohmann::ordered_json& fields) {
  if (!log_enabled(level)) return;
  logger().log(to_spdlog(level), "{}", format_log_event(event, fields));
}

}  // namespace pb
