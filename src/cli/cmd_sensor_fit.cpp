// posebench sensor-fit DATASET --out DIR: a sensor's noise model fitted to
// real frames with ground truth (simreal/sensor_fit.h): DIR/sensor_fit.json
// (the real statistics, the simulated ones with the base profile and with
// the fit, every candidate's loss), DIR/profile.yaml (a sensor a scene config
// or `twin --sensor` can name) and DIR/plots/*.png (scripts/sensor_fit_plot.py).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "cli/command.h"
#include "core/error.h"
#include "core/log.h"
#include "io/png.h"
#include "render/sensor.h"
#include "simreal/sensor_fit.h"

namespace fs = std::filesystem;

namespace {

std::string find_script(const std::string& rel) {
#ifdef POSEBENCH_SOURCE_DIR
  const fs::path p = fs::path(POSEBENCH_SOURCE_DIR) / rel;
  if (fs::exists(p)) return p.string();
#endif
  return fs::exists(rel) ? rel : "";
}

// DIR/plots/*.png through the plot script; false when it failed.
bool plot(const std::string& json, const std::string& dir) {
  const std::string script = find_script("scripts/sensor_fit_plot.py");
  if (script.empty()) throw pb::InputError("scripts/sensor_fit_plot.py", "", "plot script not found");
  const std::string py = fs::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
  const std::string cmd = py + " '" + script + "' '" + json + "' '" + (fs::path(dir) / "plots").string() + "'";
  return std::system(cmd.c_str()) == 0;
}

// The dataset as the outputs name it: under $POSEBENCH_REAL_DATA, relative
// to it (the outputs are committed; the data folder differs per machine).
std::string display_path(const std::string& dataset) {
  const char* root = std::getenv("POSEBENCH_REAL_DATA");
  if (!root || !*root) return dataset;
  const fs::path rel = fs::absolute(dataset).lexically_normal().lexically_relative(fs::absolute(root).lexically_normal());
  if (rel.empty() || *rel.begin() == "..") return dataset;
  return "${POSEBENCH_REAL_DATA}/" + rel.string();
}

int sensor_fit_main(int argc, char** argv) {
  CLI::App app{"Fit a sensor's noise model to real depth frames with ground truth (a BOP dataset):\n"
               "each annotated object's pixels against the depth rendered from its GT pose, then\n"
               "the same statistics on the frames' twins degraded by candidate noise models."};
  std::string dataset, out, base = "astra", name, split = "test";
  int images = 0, stride = 1;
  long long seed = 1;
  bool no_plots = false;
  app.add_option("dataset", dataset, "BOP dataset root (models/, SPLIT/ with depth and scene_gt.json)")->required();
  app.add_option("--out", out, "output folder")->required();
  app.add_option("--base", base, "the profile whose noise model is fitted: astra (structured light), "
                                  "kinect_one (time of flight) or a profile file")
      ->capture_default_str();
  app.add_option("--name", name, "the fitted profile's name (default: the output folder's name)");
  app.add_option("--split", split, "split folder")->capture_default_str();
  app.add_option("--images", images, "at most this many images (0 = all with depth and GT)")->capture_default_str();
  app.add_option("--stride", stride, "every N-th image (video sequences: frames apart)")->capture_default_str();
  app.add_option("--seed", seed, "seed of the simulated frames' noise")->capture_default_str();
  app.add_flag("--no-plots", no_plots, "do not draw the PNG plots");
  pb::cli::add_log_flags(app);
  PB_CLI_PARSE(app, argc, argv);
  if (images < 0) throw pb::InputError("", "--images", "must be >= 0");
  if (stride < 1) throw pb::InputError("", "--stride", "must be >= 1");
  if (seed < 0) throw pb::InputError("", "--seed", "must be non-negative");

  pb::SensorFitSettings s;
  s.split = split;
  s.base = pb::parse_sensor(pb::YamlNode::load_string(base, "--base"));
  s.name = name.empty() ? fs::path(out).lexically_normal().filename().string() : name;
  if (s.name.empty() || s.name == "." || s.name == "..") s.name = "fitted";
  s.max_images = images;
  s.stride = stride;
  s.seed = static_cast<uint64_t>(seed);
  pb::SensorFitResult r = pb::fit_sensor(dataset, s);
  r.dataset = display_path(dataset);

  fs::create_directories(out);
  const std::string json = (fs::path(out) / "sensor_fit.json").string();
  pb::atomic_write_text(json, pb::to_json(r).dump(1) + "\n");
  const std::string comment = "Fitted by: posebench sensor-fit " + r.dataset + " --base " + base + " --seed " +
                              std::to_string(seed) + (images ? " --images " + std::to_string(images) : "") +
                              (stride > 1 ? " --stride " + std::to_string(stride) : "") +
                              "\n(" + std::to_string(r.images) + " real images; statistics in sensor_fit.json)";
  pb::atomic_write_text((fs::path(out) / "profile.yaml").string(), pb::profile_yaml(r.profile, comment));
  std::printf("sensor-fit %s: %d images, %lld object pixels (%.1f%% missing, %.1f%% nearer)\n", r.dataset.c_str(),
              r.images, static_cast<long long>(r.real.all.n), 100.0 * r.real.all.missing_rate(),
              r.real.all.n ? 100.0 * r.real.all.nearer / r.real.all.n : 0.0);
  std::printf("loss: base %.3f, fitted %.3f\n", r.base_loss.total(), pb::fit_loss(r.real, r.fitted).total());
  std::printf("fitted noise: %s\n", pb::noise_json(r.profile.noise).dump().c_str());
  std::printf("wrote %s, %s\n", json.c_str(), (fs::path(out) / "profile.yaml").string().c_str());
  if (!no_plots && !plot(json, out)) {
    pb::log_event(pb::LogLevel::error, "plot_failed", {{"hint", "python3-matplotlib missing?"}});
    return 1;
  }
  return 0;
}

}  // namespace

static pb::cli::Command cmd("sensor-fit", "fit a sensor's noise model to real depth frames with ground truth",
                            sensor_fit_main);
