// posebench import-clouds --out DIR --object NAME CLOUD...: a BOP-layout
// dataset of point clouds (scenes/import_clouds.h), for `run` and `score`.
#include <iostream>

#include "cli/command.h"
#include "core/error.h"
#include "core/log.h"
#include "scenes/import_clouds.h"

static pb::cli::Command import_cmd(
    "import-clouds", "a BOP-layout dataset from point clouds (PCD, PLY), for run and score", [](int argc, char** argv) {
      CLI::App app{"Writes DIR in the BOP layout: scene 1 holds one depth image per cloud (in the order given; "
                   "organized clouds keep their grid and get intrinsics fitted to their points, unorganized ones "
                   "go through --intrinsics / --camera or a virtual 640x480 camera), no ground truth, and the "
                   "objects' models from the model registry. Experiment configs do the same with a scene set's "
                   "`clouds:` key."};
      pb::ImportCloudsSettings s;
      std::string out, units = "auto";
      app.add_option("clouds", s.clouds, "point clouds (.pcd, .ply) in the camera frame")->required();
      app.add_option("--out", out, "the dataset folder")->required();
      app.add_option("--object", s.objects, "registry model(s) to put into models/ (posebench models)")->required();
      app.add_option("--units", units, "the clouds' units: m, mm or auto (metres when the median depth < 20)");
      app.add_option("--intrinsics", s.intrinsics, "fx,fy,cx,cy[,width,height] for every cloud");
      app.add_option("--camera", s.camera, "a BOP camera.json for every cloud");
      app.add_option("--registry", s.registry, "model registry file (default: the tree's models/models.yaml)");
      pb::cli::add_log_flags(app);
      PB_CLI_PARSE(app, argc, argv);
      s.units = pb::parse_cloud_units(units, "--units");
      const pb::ImportCloudsSummary sum = pb::import_clouds(s, out);
      std::cout << "imported " << sum.images << " clouds into " << out << " (depth_scale " << sum.depth_scale
                << " mm per unit)\n";
      for (size_t i = 0; i < sum.intrinsics_source.size(); ++i)
        pb::log_event(pb::LogLevel::debug, "cloud_imported", {{"im_id", i}, {"cloud", s.clouds[i]},
                                                               {"intrinsics", sum.intrinsics_source[i]}});
      return 0;
    });
