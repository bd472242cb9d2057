// posebench twin DATASET --sensor PROFILE --out DIR: a synthetic twin of a
// real BOP dataset, one image per real image (simreal/twin.h).
#include <CLI/CLI.hpp>
#include <cstdio>

#include "cli/command.h"
#include "core/error.h"
#include "core/yaml.h"
#include "render/sensor.h"
#include "simreal/twin.h"

namespace {

int twin_main(int argc, char** argv) {
  CLI::App app{"Write the synthetic twin of a real BOP dataset: per real image with depth and\n"
               "ground truth, the same intrinsics, the annotated objects at their GT poses and the\n"
               "supporting plane fitted to the real depth, rendered with a sensor profile."};
  std::string dataset, sensor, out;
  pb::TwinSettings s;
  long long seed = 1;
  app.add_option("dataset", dataset, "real BOP dataset root")->required();
  app.add_option("--sensor", sensor, "sensor profile: a built-in name (astra, kinect_one, ...) or a profile "
                                     "file (sensor-fit's profile.yaml)")
      ->required();
  app.add_option("--out", out, "output folder (a BOP dataset)")->required();
  app.add_option("--split", s.split, "split folder")->capture_default_str();
  app.add_flag("--keep-background", s.keep_background,
               "keep the real depth wherever no annotated object is drawn");
  app.add_option("--images", s.max_images, "at most this many images (0 = all)")->capture_default_str();
  app.add_option("--seed", seed, "seed of the sensor noise")->capture_default_str();
  pb::cli::add_log_flags(app);
  PB_CLI_PARSE(app, argc, argv);
  if (s.max_images < 0) throw pb::InputError("", "--images", "must be >= 0");
  if (seed < 0) throw pb::InputError("", "--seed", "must be non-negative");
  s.seed = static_cast<uint64_t>(seed);
  const pb::SensorProfile prof = pb::parse_sensor(pb::YamlNode::load_string(sensor, "--sensor"));
  const pb::TwinSummary sum = pb::write_twin(dataset, prof, s, out);
  std::printf("twin %s: %d images of %s with sensor %s (%s)%s, supporting plane found in %d\n", out.c_str(),
              sum.images, dataset.c_str(), prof.name.c_str(), prof.noise.model.c_str(),
              s.keep_background ? ", real background kept" : "", sum.planes_found);
  return 0;
}

}  // namespace

static pb::cli::Command cmd("twin", "write a synthetic twin of a real BOP dataset (same images, GT objects, sensor model)",
                            twin_main);
