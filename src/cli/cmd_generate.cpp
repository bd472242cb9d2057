// posebench generate CONFIG.yaml [--out DIR]: a table or warehouse scene set
// with ground truth in the BOP layout (scenes/generator.h).
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <thread>

#include "cli/command.h"
#include "core/error.h"
#include "core/log.h"
#include "scenes/generator.h"

namespace {

// A bar on a terminal; elsewhere a debug log line per image.
void print_progress(int done, int total) {
  static const bool tty = isatty(2);
  if (!tty) {
    pb::log_event(pb::LogLevel::debug, "image_generated", {{"image", done}, {"of", total}});
    return;
  }
  std::fprintf(stderr, "\rgenerate: image %d / %d", done, total);
  if (done == total) std::fprintf(stderr, "\n");
}

// Applies --images, --seed and --threads (0 = one per core) to the settings.
void apply_overrides(const CLI::App& app, int images, long long seed, int& threads, pb::SceneSettings& s) {
  if (app.count("--images")) {
    if (images < 1 || images > 999999)
      throw pb::InputError("", "--images", "must be in [1, 999999], got " + std::to_string(images));
    s.images = images;
  }
  if (app.count("--seed")) {
    if (seed < 0) throw pb::InputError("", "--seed", "must be non-negative");
    s.seed = static_cast<uint64_t>(seed);
  }
  if (threads < 0 || threads > 256) throw pb::InputError("", "--threads", "must be in [0, 256]");
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
}

int generate_main(int argc, char** argv) {
  CLI::App app{"Generate a scene set with ground truth in the BOP layout:\n"
               "DIR/camera.json, DIR/models/, DIR/test/NNNNNN/{depth,mask_visib,scene_*.json},\n"
               "DIR/posebench_scene.json (resolved config) and DIR/depth_preview.png."};
  std::string config, out;
  int images = 0;
  long long seed = -1;
  bool quiet = false;
  int threads = 0;
  app.add_option("config", config, "scene config (configs/scenes/*.yaml)")->required();
  app.add_option("--out", out, "output folder (default: scenes/NAME, NAME = the config file's stem)");
  app.add_option("--images", images, "override the config's number of images");
  app.add_option("--seed", seed, "override the config's seed");
  pb::cli::add_log_flags(app, &quiet);
  app.add_option("--threads", threads, "worker threads (0 = one per core); the output is the same for any number");
  PB_CLI_PARSE(app, argc, argv);

  pb::SceneSettings s = pb::load_scene_settings(config);
  apply_overrides(app, images, seed, threads, s);
  if (out.empty()) out = (std::filesystem::path("scenes") / s.name).string();
  const pb::GenerateSummary sum = pb::generate_dataset(s, out, quiet ? nullptr : print_progress, threads);
  std::printf("generated %s: %s scenario, sensor %s, %d images, %d objects\n", sum.out_dir.c_str(),
              pb::scenario_name(s.scenario).c_str(), s.sensor.name.c_str(), sum.images, sum.objects);
  std::printf("target %s: mean visib_fract %.3f (min %.3f)\n", s.target.c_str(), sum.mean_target_visib,
              sum.min_target_visib);
  std::printf("depth preview: %s\n", sum.preview_png.c_str());
  std::printf("time: %.2f s (%.2f images/s)\n", sum.seconds, sum.images / std::max(1e-9, sum.seconds));
  return 0;
}

}  // namespace

static pb::cli::Command cmd("generate", "generate a table or warehouse scene set (BOP layout) from a YAML config",
                            generate_main);
