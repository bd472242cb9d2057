// The log line format (core/log.h): the event, then key=value per field in
// order, strings bare unless they need quotes, other values as JSON.
#include <gtest/gtest.h>

#include "core/log.h"

using namespace pb;

TEST(CoreLog, EventThenFieldsInOrder) {
  EXPECT_EQ(format_log_event("trial", {{"key", "/1/0/cvfh/icp/n0"}, {"status", "ok"}, {"correct", true},
                                       {"total_s", 0.25}}),
            "trial key=/1/0/cvfh/icp/n0 status=ok correct=true total_s=0.25");
  EXPECT_EQ(format_log_event("x", {{"message", "worker crashed (signal 11)"}, {"empty", ""}, {"eq", "a=b"}}),
            "x message=\"worker crashed (signal 11)\" empty=\"\" eq=\"a=b\"");
  EXPECT_EQ(format_log_event("resume", {}), "resume");
}

TEST(CoreLog, LevelsFilter) {
  set_log_level(LogLevel::warn);
  EXPECT_FALSE(log_enabled(LogLevel::info));
  EXPECT_TRUE(log_enabled(LogLevel::error));
  set_log_level(LogLevel::debug);
  EXPECT_TRUE(log_enabled(LogLevel::debug));
  set_log_level(LogLevel::info);
  EXPECT_FALSE(log_enabled(LogLevel::debug));
  EXPECT_TRUE(log_enabled(LogLevel::warn));
}
