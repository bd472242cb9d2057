// The results store: durable appends, torn-line recovery after a kill,
// duplicate keys ignored, and the guard against another experiment's folder.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/error.h"
#include "runner/store.h"

namespace fs = std::filesystem;

namespace {

fs::path temp_dir(const std::string& name) {
  const fs::path p = fs::temp_directory_path() / ("posebench_store_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(p);
  return p;
}

TEST(ResultStore, AppendsAndReopens) {
  const fs::path d = temp_dir("reopen");
  {
    pb::ResultStore s(d.string(), {{"name", "e"}}, "h1");
    s.append({{"key", "a"}, {"status", "ok"}});
    s.append({{"key", "b"}, {"status", "error"}});
    s.append({{"key", "a"}, {"status", "ok"}});  // duplicate: ignored
    EXPECT_EQ(s.size(), 2u);
  }
  pb::ResultStore s2(d.string(), {{"name", "e"}}, "h1");
  EXPECT_EQ(s2.size(), 2u);
  EXPECT_TRUE(s2.has("a"));
  EXPECT_TRUE(s2.has("b"));
  EXPECT_FALSE(s2.has("c"));
  fs::remove_all(d);
}

TEST(ResultStore, DropsTornLastLineOfAKilledRun) {
  const fs::path d = temp_dir("torn");
  {
    pb::ResultStore s(d.string(), {{"name", "e"}}, "h1");
    s.append({{"key", "a"}, {"status", "ok"}});
  }
  {
    std::ofstream out(d / "records.jsonl", std::ios::app);
    out << "{\"key\": \"b\", \"sta";  // killed mid-write
  }
  pb::ResultStore s(d.string(), {{"name", "e"}}, "h1");
  EXPECT_EQ(s.size(), 1u);
  EXPECT_FALSE(s.has("b"));
  s.append({{"key", "b"}, {"status", "ok"}});
  const auto recs = pb::ResultStore::read_records(d.string());
  ASSERT_EQ(recs.size(), 2u);
  EXPECT_EQ(recs[1]["key"], "b");
  fs::remove_all(d);
}

TEST(ResultStore, RefusesAnotherExperimentsFolderAndLeavesItUntouched) {
  const fs::path d = temp_dir("guard");
  {
    pb::ResultStore s(d.string(), {{"name", "first"}}, "h1");
    s.append({{"key", "a"}, {"status", "ok"}});
  }
  const auto before = fs::file_size(d / "records.jsonl");
  try {
    pb::ResultStore s(d.string(), {{"name", "second"}}, "h2");
    FAIL() << "expected InputError";
  } catch (const pb::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("experiment.json"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("another experiment"), std::string::npos) << e.what();
  }
  EXPECT_EQ(fs::file_size(d / "records.jsonl"), before);
  fs::remove_all(d);
}

TEST(ResultStore, CorruptMiddleLineIsAnInputErrorNamingTheLine) {
  const fs::path d = temp_dir("corrupt");
  fs::create_directories(d);
  {
    std::ofstream out(d / "records.jsonl");
    out << "{\"key\":\"a\"}\nnot json\n{\"key\":\"b\"}\n";
  }
  try {
    pb::ResultStore::read_records(d.string());
    FAIL() << "expected InputError";
  } catch (const pb::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("line 2"), std::string::npos) << e.what();
  }
  fs::remove_all(d);
}

}  // namespace
