// posebench bench-pipeline [CONFIG] [--out DIR] [--threads N]
//
// The per-method, per-scenario time table on this machine: runs a timing
// experiment (default configs/bench/pipeline.yaml: simulated Astra table
// frames, warehouse frames and cluttered table frames, every descriptor)
// with one worker and N OpenMP threads (default 1: one core), then writes
// DIR/bench.json and DIR/bench.md (stdout too) from the records: median
// stage times, p90 total, robustness k/n with a 95% interval, and the
// budget each scenario is held to. It is a run underneath: resumable, and
// a second call only re-summarizes.
#include <sys/utsname.h>

#include <filesystem>
#include <fstream>
#include <iostream>

#include "cli/command.h"
#include "core/error.h"
#include "io/png.h"
#include "report/bench.h"
#include "runner/runner.h"
#include "runner/store.h"

namespace fs = std::filesystem;

namespace {


std::string default_config() {
#ifdef POSEBENCH_SOURCE_DIR
  const fs::path p = fs::path(POSEBENCH_SOURCE_DIR) / "configs/bench/pipeline.yaml";
  if (fs::exists(p)) return p.string();
#endif
  return "configs/bench/pipeline.yaml";
}

std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("model name", 0) == 0) {
      const auto c = line.find(':');
      return c == std::string::npos ? line : line.substr(c + 2);
    }
  return "unknown";
}

}  // namespace

static pb::cli::Command bench_cmd(
    "bench-pipeline", "time every method per scenario on this machine (JSON + markdown table)",
    [](int argc, char** argv) {
      CLI::App app{"Runs the timing experiment (one worker, --threads OpenMP threads) and writes OUT/bench.json "
                   "and OUT/bench.md: per scene set and method the median time of each stage, the p90 total, "
                   "the robustness k/n with a 95% interval, and whether the scenario's budget is met."};
      std::string config = default_config();
      pb::RunOptions opt;
      int threads = 1;
      double table_ms = 33, warehouse_ms = 100;
      app.add_option("config", config, "timing experiment YAML")->capture_default_str();
      app.add_option("--out", opt.out_dir, "results folder (default results/NAME)");
      app.add_option("--threads", threads, "OpenMP threads of the worker (1 = one core)")
          ->check(CLI::PositiveNumber)
          ->capture_default_str();
      app.add_option("--cache", opt.cache_dir, "training cache folder ('' = none)")->capture_default_str();
      app.add_option("--scenes", opt.scenes_dir, "where generated scene sets go")->capture_default_str();
      app.add_option("--table-budget-ms", table_ms, "budget per table frame")->capture_default_str();
      app.add_option("--warehouse-budget-ms", warehouse_ms, "budget per warehouse frame")->capture_default_str();
      pb::cli::add_log_flags(app, &opt.quiet);
      PB_CLI_PARSE(app, argc, argv);

      setenv("OMP_NUM_THREADS", std::to_string(threads).c_str(), 1);  // the worker inherits it
      opt.jobs = 1;
      opt.binary = pb::cli::self_path();
      const pb::ExperimentConfig cfg = pb::load_experiment(config);
      const pb::RunSummary s = pb::run_experiment(cfg, opt);
      const std::string out = opt.out_dir.empty() ? "results/" + cfg.name : opt.out_dir;

      pb::BenchTable t = pb::bench_table(pb::ResultStore::read_records(out),
                                         {{"table", table_ms / 1000}, {"warehouse", warehouse_ms / 1000}});
      utsname u{};
      uname(&u);
      t.host = {{"cpu", cpu_model()},
                {"cores", s.host_cores},
                {"omp_threads", threads},
                {"kernel", std::string(u.release)},
                {"experiment", cfg.name},
                {"experiment_hash", cfg.hash},
                {"records", out + "/records.jsonl"}};
      // The settings as the config writes them (its canonical form).
      if (!cfg.canonical["settings"].empty()) t.settings["all"] = cfg.canonical["settings"];
      for (const nlohmann::json& src : cfg.canonical["scenes"])
        if (!src["settings"].empty()) t.settings[src["name"].get<std::string>()] = src["settings"];
      pb::atomic_write_text(out + "/bench.json", pb::bench_json(t).dump(2) + "\n");
      const std::string md = "# bench-pipeline: " + cfg.name + "\n\n" + pb::bench_markdown(t);
      pb::atomic_write_text(out + "/bench.md", md);
      std::cout << md << "\nwritten: " << out << "/bench.json, " << out << "/bench.md\n";
      return 0;
    });
