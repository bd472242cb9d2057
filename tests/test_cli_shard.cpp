// posebench run --shard I/N and posebench merge: N shards run as separate,
// concurrent processes on one results folder (sharing its scene and cache
// folders, both produced by whichever shard comes first), then merged, give
// exactly the records of one run on one machine (timing fields aside), for
// N = 1, 2, 3 and 7 of the demo experiment; a shard killed mid-way and rerun
// gives the same merged result; a plain run on a merged folder runs only what
// is missing; bad shard specs and foreign records are exit 2 with the folder
// untouched.
#include <gtest/gtest.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <map>
#include <nlohmann/json.hpp>
#include <thread>

#include "cli_test_util.h"
#include "core/file_lock.h"

namespace fs = std::filesystem;

namespace {

const std::string kSrc = POSEBENCH_SOURCE_DIR;
const std::string kDemo = "configs/experiments/demo.yaml";

// Records by key, timing aside; every run here has its own scene folder.
std::map<std::string, nlohmann::json> comparable(const std::string& records_file) {
  return pbcli::records_by_key(records_file, true);
}

std::vector<std::string> keys_in_file_order(const std::string& records_file) {
  std::vector<std::string> keys;
  std::ifstream in(records_file);
  std::string line;
  while (std::getline(in, line)) keys.push_back(nlohmann::json::parse(line)["key"]);
  return keys;
}

// Every folder of a run gets its own scenes and cache, so each sharded run
// also exercises concurrent scene generation and training.
std::string folders(const std::string& base) {
  return "-q --out '" + base + "/r' --scenes '" + base + "/scenes' --cache '" + base + "/cache'";
}

// Starts `posebench ARGS` in its own process group (so a kill reaches its
// workers too) with cwd = the source tree; returns the pid.
pid_t spawn(const std::vector<std::string>& args) {
  const pid_t pid = fork();
  if (pid == 0) {
    setpgid(0, 0);
    if (chdir(kSrc.c_str()) != 0) _exit(127);
    std::vector<char*> argv{const_cast<char*>(POSEBENCH_BINARY)};
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    const int devnull = ::open("/dev/null", O_WRONLY);
    dup2(devnull, 1);
    dup2(devnull, 2);
    execv(POSEBENCH_BINARY, argv.data());
    _exit(127);
  }
  return pid;
}

std::vector<std::string> shard_args(const std::string& base, int i, int n) {
  return {"run", kDemo, "-q", "--out", base + "/r", "--scenes", base + "/scenes", "--cache", base + "/cache",
          "--shard", std::to_string(i) + "/" + std::to_string(n)};
}

int wait_exit(pid_t pid) {
  int st = 0;
  waitpid(pid, &st, 0);
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

class ShardTest : public ::testing::Test {
 protected:
  // One single-machine run of the demo experiment: the reference.
  static void SetUpTestSuite() {
    tmp_ = new pbcli::TempDir;
    const auto r = pbcli::run("run " + kDemo + " --jobs 2 " + folders(tmp_->path + "/single"), kSrc);
    ASSERT_EQ(r.code, 0) << r.err;
    single_ = comparable(tmp_->path + "/single/r/records.jsonl");
    ASSERT_EQ(single_.size(), 16u);  // 4 images x 4 descriptors
  }
  static void TearDownTestSuite() {
    delete tmp_;
    tmp_ = nullptr;
  }
  static pbcli::TempDir* tmp_;
  static std::map<std::string, nlohmann::json> single_;
};
pbcli::TempDir* ShardTest::tmp_ = nullptr;
std::map<std::string, nlohmann::json> ShardTest::single_;

class ShardCount : public ShardTest, public ::testing::WithParamInterface<int> {};

TEST_P(ShardCount, ConcurrentShardsMergedEqualOneMachinesRecords) {
  const int n = GetParam();
  const std::string base = tmp_->path + "/n" + std::to_string(n);
  std::vector<pid_t> pids;
  for (int i = 0; i < n; ++i) pids.push_back(spawn(shard_args(base, i, n)));
  for (int i = 0; i < n; ++i) EXPECT_EQ(wait_exit(pids[static_cast<size_t>(i)]), 0) << "shard " << i << "/" << n;

  // Each shard wrote only its own file; together they cover every trial
  // once. Every model was trained once, by one shard, for all of them: the
  // others waited for its training cache file.
  size_t in_shards = 0;
  std::map<std::string, int> trained;
  for (int i = 0; i < n; ++i) {
    const std::string f = base + "/r/shards/" + std::to_string(i) + "-of-" + std::to_string(n) + ".records.jsonl";
    std::ifstream in(f);
    std::string line;
    while (std::getline(in, line)) {
      const auto j = nlohmann::json::parse(line);
      trained[j["descriptor"]] += j["train_from_cache"] == false;
    }
    const size_t k = comparable(f).size();
    EXPECT_GE(k, 16u / static_cast<size_t>(n)) << f;  // balanced: floor or ceil of 16 / n
    EXPECT_LE(k, (16u + static_cast<size_t>(n) - 1) / static_cast<size_t>(n)) << f;
    in_shards += k;
  }
  EXPECT_EQ(in_shards, 16u);
  EXPECT_EQ(trained, (std::map<std::string, int>{{"cesf", 1}, {"cvfh", 1}, {"fpfh", 1}, {"shot", 1}}));
  EXPECT_FALSE(fs::exists(base + "/r/records.jsonl"));

  // Before the merge the reporter says what to do.
  const auto early = pbcli::run("report '" + base + "/r' --format csv", kSrc);
  EXPECT_EQ(early.code, 2) << early.err;
  EXPECT_NE(early.err.find("posebench merge"), std::string::npos) << early.err;

  const auto m = pbcli::run("merge '" + base + "/r' --require-complete", kSrc);
  ASSERT_EQ(m.code, 0) << m.out << m.err;
  EXPECT_NE(m.out.find("merged 16 of 16 trials"), std::string::npos) << m.out;
  EXPECT_EQ(comparable(base + "/r/records.jsonl"), single_);

  // Canonical order: the experiment's trial order, whatever N was.
  const auto order = keys_in_file_order(base + "/r/records.jsonl");
  std::ifstream tl(base + "/r/trials.json");
  EXPECT_EQ(order, nlohmann::json::parse(tl)["keys"].get<std::vector<std::string>>());

  // The reporter reads the merged folder: the same robustness cells as the
  // single run's (times differ: concurrent shards share two cores).
  for (const std::string d : {base + "/r", tmp_->path + "/single/r"})
    ASSERT_EQ(pbcli::run("report '" + d + "' --format csv", kSrc).code, 0) << d;
  const auto cells = [](const std::string& csv) {
    std::vector<std::string> rows;
    std::istringstream in(pbcli::slurp(csv));
    std::string line;
    while (std::getline(in, line))
      if (line.find(",time,") == std::string::npos) rows.push_back(line);
    return rows;
  };
  EXPECT_EQ(cells(base + "/r/report.csv"), cells(tmp_->path + "/single/r/report.csv"));
}

INSTANTIATE_TEST_SUITE_P(Demo, ShardCount, ::testing::Values(1, 2, 3, 7),
                         [](const auto& info) { return "N" + std::to_string(info.param); });

TEST_F(ShardTest, KilledShardRerunGivesTheSameMergedRecords) {
  const std::string base = tmp_->path + "/killed";
  const std::string file = base + "/r/shards/0-of-2.records.jsonl";
  // Shard 1/2 runs whole; shard 0/2 is killed (SIGKILL to it and its
  // workers) after its first record.
  ASSERT_EQ(wait_exit(spawn(shard_args(base, 1, 2))), 0);
  const pid_t pid = spawn(shard_args(base, 0, 2));
  for (int i = 0; i < 6000; ++i) {
    const std::string text = pbcli::slurp(file);
    if (std::count(text.begin(), text.end(), '\n') >= 1) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  kill(-pid, SIGKILL);
  waitpid(pid, nullptr, 0);
  const size_t partial = comparable(file).size();
  EXPECT_GE(partial, 1u);
  EXPECT_LT(partial, 8u) << "the shard finished before it could be killed";
  // A kill during an append leaves a torn last line: add one.
  std::ofstream(file, std::ios::app) << "{\"key\":\"table_synthetic/1/3/sh";

  // Merging now: what is there, the rest listed as missing (exit 1 asked for).
  const auto m1 = pbcli::run("merge '" + base + "/r' --require-complete", kSrc);
  EXPECT_EQ(m1.code, 1) << m1.out << m1.err;
  EXPECT_NE(m1.out.find(std::to_string(16 - 8 + partial) + " of 16"), std::string::npos) << m1.out;
  EXPECT_NE(m1.out.find(std::to_string(8 - partial) + " trials missing"), std::string::npos) << m1.out;

  // The rerun runs only the rest of its trials.
  std::string cmd;
  for (const auto& a : shard_args(base, 0, 2)) cmd += "'" + a + "' ";
  const auto rerun = pbcli::run(cmd, kSrc);
  ASSERT_EQ(rerun.code, 0) << rerun.err;
  EXPECT_NE(rerun.out.find(std::to_string(partial) + " already recorded, " + std::to_string(8 - partial) + " run now"),
            std::string::npos)
      << rerun.out;
  const auto m2 = pbcli::run("merge '" + base + "/r' --require-complete", kSrc);
  ASSERT_EQ(m2.code, 0) << m2.out << m2.err;
  EXPECT_EQ(comparable(base + "/r/records.jsonl"), single_);
}

TEST_F(ShardTest, PlainRunOnAMergedFolderRunsOnlyWhatIsMissing) {
  const std::string base = tmp_->path + "/partial";
  for (int i : {0, 2}) ASSERT_EQ(wait_exit(spawn(shard_args(base, i, 3))), 0);
  const auto m = pbcli::run("merge '" + base + "/r'", kSrc);
  ASSERT_EQ(m.code, 0) << m.err;
  const size_t merged = comparable(base + "/r/records.jsonl").size();
  EXPECT_NE(m.out.find(std::to_string(16 - merged) + " trials missing"), std::string::npos) << m.out;
  const auto r = pbcli::run("run " + kDemo + " " + folders(base), kSrc);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find(std::to_string(merged) + " already recorded, " + std::to_string(16 - merged) + " run now"),
            std::string::npos)
      << r.out;
  EXPECT_EQ(comparable(base + "/r/records.jsonl"), single_);

  // A shard started afterwards finds its trials recorded by the plain run.
  const auto s = pbcli::run("run " + kDemo + " " + folders(base) + " --shard 1/3", kSrc);
  ASSERT_EQ(s.code, 0) << s.err;
  EXPECT_NE(s.out.find(" 0 run now"), std::string::npos) << s.out;
}

TEST_F(ShardTest, BadShardSpecsAreExit2NamingTheOption) {
  const std::string base = tmp_->path + "/bad";
  for (const std::string spec : {"3/2", "2/2", "0/0", "-1/2", "1", "a/b", "1/2/3", ""}) {
    const auto r = pbcli::run("run " + kDemo + " " + folders(base) + " --shard '" + spec + "'", kSrc);
    EXPECT_EQ(r.code, 2) << spec << ": " << r.err;
    EXPECT_NE(r.err.find("--shard"), std::string::npos) << spec << ": " << r.err;
    EXPECT_FALSE(fs::exists(base + "/r")) << spec;
  }
  const auto r = pbcli::run("run " + kDemo + " " + folders(base) + " --shard 3/2", kSrc);
  EXPECT_NE(r.err.find("below N"), std::string::npos) << r.err;
}

TEST_F(ShardTest, TheSameShardTwiceAtOnceIsExit2) {
  const std::string base = tmp_->path + "/twice";
  fs::create_directories(base + "/r/shards");
  const pb::FileLock held = pb::FileLock::try_acquire(base + "/r/shards/0-of-2.lock");  // "the other process"
  ASSERT_TRUE(held.held());
  const auto r = pbcli::run("run " + kDemo + " " + folders(base) + " --shard 0/2", kSrc);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("another posebench process"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(base + "/r/shards/0-of-2.records.jsonl"));
}

TEST_F(ShardTest, MergeOfAnotherExperimentsRecordsIsExit2AndTouchesNothing) {
  const std::string base = tmp_->path + "/foreign";
  ASSERT_EQ(wait_exit(spawn(shard_args(base, 0, 2))), 0);
  ASSERT_EQ(pbcli::run("merge '" + base + "/r'", kSrc).code, 0);
  // Another experiment: the demo with another seed, run as shard 1/2.
  const std::string other_yaml = tmp_->path + "/other.yaml";
  pbcli::write_file(other_yaml, pbcli::slurp(kSrc + "/" + kDemo) + "\n");
  {
    std::string text = pbcli::slurp(other_yaml);
    text.replace(text.find("seed: 1"), 7, "seed: 2");
    pbcli::write_file(other_yaml, text);
  }
  const std::string other = tmp_->path + "/foreign_other";
  ASSERT_EQ(pbcli::run("run '" + other_yaml + "' " + folders(other) + " --shard 1/2", kSrc).code, 0);
  const std::string before = pbcli::slurp(base + "/r/records.jsonl");

  // merge DIR FROM with FROM of another experiment.
  const auto a = pbcli::run("merge '" + base + "/r' '" + other + "/r'", kSrc);
  EXPECT_EQ(a.code, 2) << a.out << a.err;
  EXPECT_NE(a.err.find(other + "/r/experiment.json"), std::string::npos) << a.err;
  EXPECT_NE(a.err.find("another experiment"), std::string::npos) << a.err;
  EXPECT_EQ(pbcli::slurp(base + "/r/records.jsonl"), before);

  // A shard of the other experiment copied into DIR/shards.
  for (const char* f : {"1-of-2.records.jsonl", "1-of-2.json"})
    fs::copy_file(other + "/r/shards/" + f, base + "/r/shards/" + f);
  const auto b = pbcli::run("merge '" + base + "/r'", kSrc);
  EXPECT_EQ(b.code, 2) << b.out << b.err;
  EXPECT_NE(b.err.find("1-of-2.records.jsonl"), std::string::npos) << b.err;
  EXPECT_NE(b.err.find("another experiment"), std::string::npos) << b.err;
  EXPECT_EQ(pbcli::slurp(base + "/r/records.jsonl"), before);

  // Its header removed: which experiment it belongs to is unknown.
  fs::remove(base + "/r/shards/1-of-2.json");
  const auto c = pbcli::run("merge '" + base + "/r'", kSrc);
  EXPECT_EQ(c.code, 2) << c.out << c.err;
  EXPECT_NE(c.err.find("1-of-2.json"), std::string::npos) << c.err;
  EXPECT_EQ(pbcli::slurp(base + "/r/records.jsonl"), before);
  fs::remove(base + "/r/shards/1-of-2.records.jsonl");

  // A shard with this experiment's header but a record of no trial of it.
  std::string line = pbcli::slurp(base + "/r/shards/0-of-2.records.jsonl");
  line = line.substr(0, line.find('\n'));
  auto rec = nlohmann::json::parse(line);
  rec["key"] = "elsewhere/1/0/cvfh/icp/{}/noise=0.0";
  pbcli::write_file(base + "/r/shards/1-of-2.records.jsonl", rec.dump() + "\n");
  fs::copy_file(base + "/r/shards/0-of-2.json", base + "/r/shards/1-of-2.json");
  const auto d = pbcli::run("merge '" + base + "/r'", kSrc);
  EXPECT_EQ(d.code, 2) << d.out << d.err;
  EXPECT_NE(d.err.find("'elsewhere/1/0/cvfh/icp/{}/noise=0.0' is not a trial of this experiment"), std::string::npos)
      << d.err;
  EXPECT_EQ(pbcli::slurp(base + "/r/records.jsonl"), before);
}

}  // namespace
