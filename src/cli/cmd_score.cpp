// posebench score --dataset DIR RESULTS.csv: BOP scores of any tool's results.
#include <filesystem>
#include <iostream>

#include "cli/command.h"
#include "core/error.h"
#include "io/png.h"
#include "report/score_report.h"

static pb::cli::Command score_cmd(
    "score", "BOP scores (MSSD, MSPD, VSD, AR) of any tool's BOP results CSV", [](int argc, char** argv) {
      CLI::App app{"Scores a BOP results file (bop19 CSV: scene_id,im_id,obj_id,score,R,t,time; from posebench "
                   "or any other tool) against a BOP dataset as bop_toolkit's eval_bop19_pose.py does: per test "
                   "target its inst_count most visible GT instances, the top inst_count estimates by score, "
                   "MSSD, MSPD and VSD, recall per threshold and AR. MSSD and MSPD use the model vertices "
                   "(models/), not models_eval/. A malformed file (column count, a number, R not a rotation, "
                   "two times for one image) is exit 2 naming the line and the field."};
      pb::ScoreSettings s;
      std::string out;
      bool no_vsd = false;
      app.add_option("results", s.results, "results CSV, named METHOD_DATASET-SPLIT.csv")->required();
      app.add_option("--dataset", s.dataset, "BOP dataset folder (models/, SPLIT/)")->required();
      app.add_option("--targets", s.targets,
                     "test targets JSON (default: DATASET/test_targets_bop19.json when present, else every GT "
                     "instance of the split)");
      app.add_option("--split", s.split, "split folder (default: from the file name)");
      app.add_flag("--no-vsd", no_vsd, "skip VSD (no rendering): AR is then the mean of AR_MSSD and AR_MSPD");
      app.add_option("--vsd-delta", s.vsd_delta_mm, "VSD visibility tolerance in mm (bop19: 15; ITODD 5)");
      app.add_option("--out", out, "also write OUT/scores.json (totals, recalls, every estimate's errors) and "
                                   "OUT/scores.md");
      pb::cli::add_log_flags(app);
      PB_CLI_PARSE(app, argc, argv);
      s.vsd = !no_vsd;
      const pb::ScoreResult r = pb::score_bop_results(s);
      const std::string md = pb::score_markdown(r);
      std::cout << md;
      if (!out.empty()) {
        std::filesystem::create_directories(out);
        pb::atomic_write_text((std::filesystem::path(out) / "scores.json").string(), pb::score_json(r).dump(2) + "\n");
        pb::atomic_write_text((std::filesystem::path(out) / "scores.md").string(), md);
      }
      return 0;
    });
