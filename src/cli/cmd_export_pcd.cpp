// posebench export-pcd --dataset DIR --scene S --image I --out FILE.pcd: one
// depth image of a BOP dataset as an organized PCD (CloudCompare, pcl_viewer).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>

#include "cli/command.h"
#include "core/error.h"
#include "io/bop.h"
#include "io_pcl/pcd.h"

static pb::cli::Command cmd(
    "export-pcd", "write one image of a BOP dataset as an organized PCD", [](int argc, char** argv) {
      CLI::App app{"Export the depth image of a BOP dataset (ours or a real one) as an organized\n"
                   "PCD: width x height points, x y z in the camera frame (mm, or m with --metres),\n"
                   "NaN where there is no depth."};
      std::string dataset, out, split = "test";
      int scene = -1, image = -1;
      bool metres = false;
      std::string encoding = "binary";
      app.add_option("--dataset", dataset, "dataset root (with models/ and test/)")->required();
      app.add_option("--scene", scene, "scene id")->required();
      app.add_option("--image", image, "image id")->required();
      app.add_option("--split", split, "split folder")->capture_default_str();
      app.add_option("--out", out, "output .pcd file")->required();
      app.add_flag("--metres", metres, "write coordinates in metres instead of millimetres");
      app.add_option("--encoding", encoding, "PCD data: binary, binary_compressed or ascii")
          ->check(CLI::IsMember({"binary", "binary_compressed", "ascii"}))
          ->capture_default_str();
      PB_CLI_PARSE(app, argc, argv);

      const pb::BopDataset ds(dataset);
      const auto scenes = ds.scene_ids(split);
      if (std::find(scenes.begin(), scenes.end(), scene) == scenes.end())
        throw pb::InputError(dataset, "--scene", "no scene " + std::to_string(scene) + " in split '" + split + "'");
      const pb::SceneInfo si = ds.load_scene(split, scene);
      const auto it = si.images.find(image);
      if (it == si.images.end())
        throw pb::InputError(ds.scene_dir(split, scene), "--image",
                             "no image " + std::to_string(image) + " in scene " + std::to_string(scene));
      const pb::DepthImage depth = ds.load_depth(split, scene, it->second);
      const pb::OrganizedCloud cloud = pb::OrganizedCloud::from_depth(depth, it->second.K);
      pb::write_organized_pcd(out, cloud, metres ? 0.001 : 1.0,
                              encoding == "ascii"    ? pb::PcdEncoding::ascii
                              : encoding == "binary" ? pb::PcdEncoding::binary
                                                     : pb::PcdEncoding::binary_compressed);
      std::printf("wrote %s: %d x %d organized, %zu valid points (%s)\n", out.c_str(), cloud.width, cloud.height,
                  cloud.valid_count(), metres ? "m" : "mm");
      return 0;
    });
