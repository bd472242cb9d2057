// The results store: durable appends, torn-line recovery after a kill,
// duplicate keys ignored, and the guard against another experiment's folder.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/error.h"
#include "runner/store.h"

namespace fs = std::filesystem;

namespace {

// A complete record (every required key) with this key and status.
pb::TrialRecord record(const std::string& key, const std::string& status) {
  pb::TrialRecord r;
  r.key = key;
  r.scene = "table";
  r.scenario = "table";
  r.dataset = "d";
  r.split = "test";
  r.descriptor = "fpfh";
  r.refinement = "icp";
  r.status = status;
  return r;
}

fs::path temp_dir(const std::string& name) {
  const fs::path p = fs::temp_directory_path() / ("posebench_store_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(p);
  return p;
}

TEST(ResultStore, AppendsAndReopens) {
  const fs::path d = temp_dir("reopen");
  {
    pb::ResultStore s(d.string(), {{"name", "e"}}, "h1");
    s.append(record("a", "ok"));
    s.append(record("b", "error"));
    s.append(record("a", "ok"));  // duplicate: ignored
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
    s.append(record("a", "ok"));
  }
  {
    std::ofstream out(d / "records.jsonl", std::ios::app);
    out << "{\"key\": \"b\", \"sta";  // killed mid-write
  }
  pb::ResultStore s(d.string(), {{"name", "e"}}, "h1");
  EXPECT_EQ(s.size(), 1u);
  EXPECT_FALSE(s.has("b"));
  s.append(record("b", "ok"));
  const auto recs = pb::ResultStore::read_records(d.string());
  ASSERT_EQ(recs.size(), 2u);
  EXPECT_EQ(recs[1].key, "b");
  fs::remove_all(d);
}

TEST(ResultStore, RefusesAnotherExperimentsFolderAndLeavesItUntouched) {
  const fs::path d = temp_dir("guard");
  {
    pb::ResultStore s(d.string(), {{"name", "first"}}, "h1");
    s.append(record("a", "ok"));
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
    out << nlohmann::json(record("a", "ok")).dump() << "\nnot json\n" << nlohmann::json(record("b", "ok")).dump() << "\n";
  }
  try {
    pb::ResultStore::read_records(d.string());
    FAIL() << "expected InputError";
  } catch (const pb::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("line 2"), std::string::npos) << e.what();
  }
  fs::remove_all(d);
}

// Records are read strictly: a misspelt key (here "statsu" for "status") is
// an error naming the file, the line and the key, not a record with a
// default status; so is a record missing a required key.
TEST(ResultStore, MisspeltOrMissingKeyIsAnInputErrorNamingFileLineAndKey) {
  const fs::path d = temp_dir("misspelt");
  fs::create_directories(d);
  nlohmann::json bad = record("b", "ok");
  bad.erase("status");
  bad["statsu"] = "ok";
  {
    std::ofstream out(d / "records.jsonl");
    out << nlohmann::json(record("a", "ok")).dump() << "\n" << bad.dump() << "\n";
  }
  try {
    pb::ResultStore::read_records(d.string());
    FAIL() << "expected InputError";
  } catch (const pb::InputError& e) {
    const std::string w = e.what();
    EXPECT_EQ(e.file(), (d / "records.jsonl").string());
    EXPECT_NE(w.find("line 2"), std::string::npos) << w;
    EXPECT_TRUE(w.find("'statsu'") != std::string::npos || w.find("'status'") != std::string::npos) << w;
  }
  nlohmann::json unknown = record("c", "ok");
  unknown["statsu"] = "ok";
  {
    std::ofstream out(d / "records.jsonl");
    out << unknown.dump() << "\n";
  }
  try {
    pb::ResultStore::read_records(d.string());
    FAIL() << "expected InputError";
  } catch (const pb::InputError& e) {
    const std::string w = e.what();
    EXPECT_NE(w.find("line 1"), std::string::npos) << w;
    EXPECT_NE(w.find("unknown key"), std::string::npos) << w;
    EXPECT_NE(w.find("'statsu'"), std::string::npos) << w;
  }
  fs::remove_all(d);
}

// Every record written reads back equal, key for key (the typed record
// round-trips), including the optional parts.
TEST(TrialRecord, RoundTripsThroughJson) {
  pb::TrialRecord r = record("k", "ok");
  r.params = {{"global.top_k", 3}};
  r.seed = 18446744073709551615ull;
  r.estimate = pb::PoseRecord{{1, 0, 0, 0, 1, 0, 0, 0, 1}, {1.5, -2, 700}};
  r.errors = pb::ThesisErrorsRecord{1.25, 0.001, 2.5, 3, 4.0, 0.2};
  r.bop = pb::BopErrorsRecord{1, 2, {0.1, 0.2}, 150, 640};
  r.judgements["faces"] = pb::JudgementRecord{true, 1.0, 0.002};
  const nlohmann::json j = r;
  const pb::TrialRecord back = pb::record_from_json(j, "f", 1);
  EXPECT_EQ(nlohmann::json(back), j);
  EXPECT_FALSE(j.contains("message"));  // absent optionals are not written
  EXPECT_EQ(j["judgements"]["faces"]["correct"], true);
  nlohmann::json wrong = j;
  wrong["estimate"]["t"] = {1, 2};
  EXPECT_THROW(pb::record_from_json(wrong, "f", 7), pb::InputError);
  wrong = j;
  wrong["scene_id"] = "one";
  EXPECT_THROW(pb::record_from_json(wrong, "f", 7), pb::InputError);
}

}  // namespace
