// posebench advise MESH [--sensor astra] [--budget-ms 100] [--images 30] [--out DIR]
#include <filesystem>
#include <iostream>

#include "cli/command.h"
#include "io/png.h"
#include "runner/advise.h"
#include "runner/experiment.h"
#include "runner/runner.h"
#include "runner/store.h"

static pb::cli::Command advise_cmd(
    "advise", "which method, refinement and length scale recognize one mesh best with one sensor",
    [](int argc, char** argv) {
      CLI::App app{"Generates table scenes of MESH (with distractors of its size) seen by SENSOR, runs every "
                   "descriptor x refinement x length scale on them (a `posebench run`: deterministic for a seed, "
                   "resumable), prints the cells ranked by robustness (k of n, Wilson 95% interval), accuracy and "
                   "time, and writes the best as OUT/best.yaml, an experiment `posebench run` reproduces."};
      pb::AdviseOptions opt;
      std::string out;
      pb::RunOptions run;
      run.jobs = 1;
      app.add_option("mesh", opt.mesh, "the object's mesh (OBJ, PLY, STL, OFF, ...)")->required();
      app.add_option("--mesh-scale", opt.mesh_scale, "file units -> mm (default 1: the file is in mm)")
          ->check(CLI::PositiveNumber);
      app.add_option("--up", opt.up, "the file's up axis (+x -x +y -y +z -z)");
      app.add_option("--sensor", opt.sensor, "synthetic | astra | kinect_one");
      app.add_option("--scenario", opt.scenario, "table");
      app.add_option("--images", opt.images, "generated images")->check(CLI::PositiveNumber);
      app.add_option("--budget-ms", opt.budget_ms, "cells over this median time per image rank last");
      app.add_option("--seed", opt.seed, "seeds the scenes and every trial");
      app.add_option("--methods", opt.descriptors, "descriptors to try (default: all)")->delimiter(',');
      app.add_option("--refinements", opt.refinements, "refinements to try (default: icp,icp_plane)")->delimiter(',');
      app.add_option("--length-factors", opt.length_factors,
                     "scale.length_factor values: every relative length x this (default 0.7,1,1.4)")
          ->delimiter(',');
      app.add_option("--out", out, "output folder (default advise_STEM)");
      app.add_option("--jobs,-j", run.jobs, "parallel worker processes")->check(CLI::PositiveNumber);
      app.add_option("--cache", run.cache_dir, "training cache folder ('' = none)");
      app.add_option("--scenes", run.scenes_dir, "where generated scene sets go");
      pb::cli::add_log_flags(app, &run.quiet);
      PB_CLI_PARSE(app, argc, argv);
      if (out.empty()) out = "advise_" + std::filesystem::path(opt.mesh).stem().string();

      const pb::AdviceInputs in = pb::write_advice_inputs(opt, out);
      for (const std::string& w : in.warnings) std::cerr << "posebench advise: warning: " << w << "\n";
      run.binary = pb::cli::self_path();
      run.out_dir = out + "/run";
      const pb::ExperimentConfig cfg = pb::load_experiment(in.experiment);
      const pb::RunSummary s = pb::run_experiment(cfg, run);
      const auto rows = pb::rank_advice(pb::ResultStore::read_records(run.out_dir), opt.budget_ms);
      std::cout << in.object << ": diameter " << in.diameter_mm << " mm, " << opt.sensor << ", " << opt.images
                << " images; correct = translation < " << in.translation_mm
                << " mm (a quarter of the diameter) and 1 - |p.q| < 0.05; " << s.total << " trials ("
                << s.already_done << " already recorded)\n\n"
                << pb::advice_table(rows, opt.budget_ms);
      if (rows.empty()) return 1;
      pb::atomic_write_text(out + "/best.yaml", pb::best_experiment_yaml(rows.front(), opt, in));
      std::cout << "\nbest: " << rows.front().descriptor << " + " << rows.front().refinement << ", lengths x"
                << rows.front().length_factor << ": " << out << "/best.yaml (posebench run " << out
                << "/best.yaml --out DIR)\n";
      return 0;
    });
