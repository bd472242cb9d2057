// The results store: durable appends, torn-line recovery after a kill,
// duplicate keys ignored, and the guard against another experiment's folder.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <vector>

#include "core/error.h"
#include "runner/store.h"
#include "runner_test_util.h"

namespace fs = std::filesystem;

namespace {

using pbtest::record;

// The trial part of a record as the runner wrote it before the typed record
// (the same keys today).
nlohmann::json old_trial(const std::string& key) {
  return {{"key", key},       {"scene", "table_synthetic"}, {"scenario", "table"},   {"dataset", "scenes/t"},
          {"split", "test"},  {"scene_id", 1},              {"im_id", 3},            {"descriptor", "cvfh"},
          {"refinement", "icp"}, {"params", nlohmann::json::object()}, {"added_noise_mm", 0.0},
          {"settings", {{"descriptor", "cvfh"}, {"refinement", "icp"}}}, {"seed", 12345678901234ull}};
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

// Records written before the typed record read back and write out the same:
// a worker that crashed or timed out left the trial, status, message and
// correct = false (no wall_s, no times); an image without the object's
// ground truth left no `correct`.
TEST(TrialRecord, RecordsOfBeforeTheTypedRecordReadBackUnchanged) {
  std::vector<nlohmann::json> old;
  nlohmann::json crashed = old_trial("a");
  crashed["status"] = "error";
  crashed["message"] = "worker crashed (signal 11); see r/workers.log";
  crashed["correct"] = false;
  old.push_back(crashed);
  nlohmann::json timeout = old_trial("b");
  timeout["status"] = "timeout";
  timeout["message"] = "exceeded the time limit of 300.000000 s";
  timeout["correct"] = false;
  old.push_back(timeout);
  nlohmann::json no_gt = old_trial("c");
  no_gt.update({{"status", "no_hypothesis"}, {"obj_id", 2}, {"settings_resolved", {{"seed", 1}}},
                {"train_s", 0.5}, {"train_from_cache", false}, {"hypotheses", 0}, {"wall_s", 1.5},
                {"times", {{"preprocess", 0.1}, {"describe", 0.2}, {"match", 0}, {"group", 0},
                           {"initial_pose", 0}, {"refine", 0}, {"verify", 0}, {"total", 0.3}}}});
  old.push_back(no_gt);
  const fs::path d = temp_dir("old");
  fs::create_directories(d);
  {
    std::ofstream out(d / "records.jsonl");
    for (const auto& j : old) out << j.dump() << "\n";
  }
  const auto recs = pb::ResultStore::read_records(d.string());
  ASSERT_EQ(recs.size(), old.size());
  for (size_t i = 0; i < old.size(); ++i) EXPECT_EQ(nlohmann::json(recs[i]), old[i]) << old[i].dump();
  EXPECT_FALSE(recs[0].wall_s.has_value());
  EXPECT_EQ(recs[0].correct, false);
  EXPECT_FALSE(recs[2].correct.has_value());
  fs::remove_all(d);
}

// What a status requires: an ok record has its estimate (and the rest of a
// finished trial); an ok record with ground truth has its judgement.
TEST(TrialRecord, KeysRequiredByTheStatusAreErrorsNamingTheKey) {
  const nlohmann::json ok = record("k", "ok");
  EXPECT_NO_THROW(pb::record_from_json(ok, "f", 1));
  nlohmann::json j = ok;
  j.erase("estimate");
  try {
    pb::record_from_json(j, "records.jsonl", 4);
    FAIL() << "no error";
  } catch (const pb::InputError& e) {
    const std::string w = e.what();
    EXPECT_EQ(e.file(), "records.jsonl");
    EXPECT_NE(w.find("line 4"), std::string::npos) << w;
    EXPECT_NE(w.find("'estimate'"), std::string::npos) << w;
    EXPECT_NE(w.find("status ok"), std::string::npos) << w;
  }
  j["status"] = "no_hypothesis";  // no estimate needed
  EXPECT_NO_THROW(pb::record_from_json(j, "f", 1));

  nlohmann::json judged = ok;
  judged["gt"] = judged["estimate"];
  try {
    pb::record_from_json(judged, "records.jsonl", 9);
    FAIL() << "no error";
  } catch (const pb::InputError& e) {
    const std::string w = e.what();
    EXPECT_NE(w.find("line 9"), std::string::npos) << w;
    EXPECT_TRUE(w.find("'correct'") != std::string::npos || w.find("'errors'") != std::string::npos ||
                w.find("'bop'") != std::string::npos)
        << w;
  }
  judged["correct"] = true;
  judged["errors"] = {{"translation_mm", 1}, {"rotation_1mpq", 0.01}, {"rotation_deg", 2}, {"symmetry", 0},
                      {"translation_mm_plain", 1}, {"rotation_1mpq_plain", 0.01}};
  judged["bop"] = {{"mssd_mm", 1}, {"mspd_px", 2}, {"vsd", {0.1}}, {"diameter", 150}, {"image_width", 640}};
  EXPECT_NO_THROW(pb::record_from_json(judged, "f", 1));
}

// The schema says which keys each status requires, as the reader checks.
TEST(TrialRecord, SchemaNamesTheRequirementOfEveryKey) {
  const nlohmann::json s = pb::record_schema();
  EXPECT_EQ(s["fields"]["key"]["required"], true);
  EXPECT_EQ(s["fields"]["status"]["required"], true);
  EXPECT_EQ(s["fields"]["estimate"]["required"], "when_ok");
  EXPECT_EQ(s["fields"]["wall_s"]["required"], "when_ok");
  EXPECT_EQ(s["fields"]["errors"]["required"], "when_gt");
  EXPECT_EQ(s["fields"]["correct"]["required"], "when_gt");
  EXPECT_EQ(s["fields"]["gt"]["required"], false);
  EXPECT_EQ(s["fields"]["times"]["fields"]["total"]["required"], true);
  EXPECT_EQ(s["fields"]["params"]["free"], true);
  EXPECT_TRUE(s["notes"].is_array());
}

}  // namespace
