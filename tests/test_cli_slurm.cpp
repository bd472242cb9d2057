// The sweep scripts on a real Slurm: scripts/slurm/local_cluster.sh starts a
// one-node cluster (Debian's slurm-wlm and munge, daemons as root), the demo
// experiment is submitted with scripts/slurm/submit.sh as a 3-task job array
// plus the dependent merge job, and the merged records equal those of one
// run on one machine (timing fields aside). Skipped, with the reason, where
// slurmctld is not installed or the test does not run as root; scripts/test.sh
// installs the packages, so CI runs it.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <thread>

#include "cli_test_util.h"

namespace fs = std::filesystem;

namespace {

const std::string kSrc = POSEBENCH_SOURCE_DIR;

struct Shell {
  int code = -1;
  std::string out;
};

// Runs a shell command in the source tree, stdout and stderr together.
Shell sh(const std::string& cmd) {
  char buf[] = "/tmp/posebench_slurm_out_XXXXXX";
  const int fd = mkstemp(buf);
  close(fd);
  const int st = std::system(("cd '" + kSrc + "' && (" + cmd + ") >'" + buf + "' 2>&1").c_str());
  Shell r{WIFEXITED(st) ? WEXITSTATUS(st) : -1, pbcli::slurp(buf)};
  fs::remove(buf);
  return r;
}

std::map<std::string, nlohmann::json> comparable(const std::string& records_file) {
  return pbcli::records_by_key(records_file, true);  // the cluster run has its own scene folder
}

// JobState of every line `scontrol show job ID` prints (one per array task).
std::vector<std::string> job_states(const std::string& id) {
  const Shell s = sh("scontrol -o show job " + id);
  std::vector<std::string> states;
  const std::regex re("JobState=([A-Z_]+)");
  for (auto it = std::sregex_iterator(s.out.begin(), s.out.end(), re); it != std::sregex_iterator(); ++it)
    states.push_back((*it)[1]);
  return states;
}

bool finished(const std::vector<std::string>& states) {
  if (states.empty()) return false;
  for (const auto& s : states)
    if (s == "PENDING" || s == "RUNNING" || s == "CONFIGURING" || s == "COMPLETING") return false;
  return true;
}

TEST(Slurm, ThreeTaskArrayAndMergeGiveOneMachinesRecords) {
  if (!fs::exists("/usr/sbin/slurmctld"))
    GTEST_SKIP() << "slurmctld is not installed (Debian slurm-wlm and munge; scripts/setup.sh installs them): "
                    "the single-node Slurm test is skipped";
  if (geteuid() != 0) GTEST_SKIP() << "the single-node Slurm runs its daemons as root; this test is not root";
  pbcli::TempDir tmp;
  const std::string state = tmp.path + "/slurm";
  const Shell start = sh("scripts/slurm/local_cluster.sh start '" + state + "'");
  struct Stop {
    std::string state;
    ~Stop() { sh("scripts/slurm/local_cluster.sh stop '" + state + "'"); }
  } stop{state};
  ASSERT_EQ(start.code, 0) << start.out << pbcli::slurp(state + "/slurmctld.log") << pbcli::slurp(state + "/slurmd.log");
  setenv("SLURM_CONF", (state + "/slurm.conf").c_str(), 1);

  const Shell single = sh("'" + std::string(POSEBENCH_BINARY) + "' run configs/experiments/demo.yaml --jobs 2 -q --out '" +
                          tmp.path + "/single/r' --scenes '" + tmp.path + "/single/scenes' --cache '" + tmp.path +
                          "/single/cache'");
  ASSERT_EQ(single.code, 0) << single.out;

  const std::string out = tmp.path + "/cluster/r";
  const Shell submit = sh("POSEBENCH='" + std::string(POSEBENCH_BINARY) +
                          "' scripts/slurm/submit.sh configs/experiments/demo.yaml 3 '" + out + "' -- --scenes '" +
                          tmp.path + "/cluster/scenes' --cache '" + tmp.path + "/cluster/cache'");
  ASSERT_EQ(submit.code, 0) << submit.out;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(submit.out, m, std::regex("array (\\d+)\\s+merge (\\d+)"))) << submit.out;
  const std::string array = m[1], merge = m[2];

  std::vector<std::string> merge_state;
  for (int i = 0; i < 1200 && !finished(merge_state = job_states(merge)); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(250));
  ASSERT_TRUE(finished(merge_state)) << "the merge job did not finish in 5 minutes\n"
                                     << sh("squeue").out << pbcli::slurp(state + "/slurmctld.log");
  const auto array_states = job_states(array);
  EXPECT_EQ(array_states, std::vector<std::string>(3, "COMPLETED")) << sh("scontrol -o show job " + array).out;
  EXPECT_EQ(merge_state, std::vector<std::string>{"COMPLETED"}) << pbcli::slurp(out + "/slurm/merge.out");
  for (int i = 0; i < 3; ++i)
    EXPECT_TRUE(fs::exists(out + "/shards/" + std::to_string(i) + "-of-3.records.jsonl")) << i;
  EXPECT_NE(pbcli::slurp(out + "/slurm/merge.out").find("merged 16 of 16 trials"), std::string::npos)
      << pbcli::slurp(out + "/slurm/merge.out");

  const auto want = comparable(tmp.path + "/single/r/records.jsonl");
  ASSERT_EQ(want.size(), 16u);
  EXPECT_EQ(comparable(out + "/records.jsonl"), want);
}

}  // namespace
