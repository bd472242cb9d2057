// posebench render-views MODEL --views N --out DIR: training views of a model
// (scenes/views.h), each as a depth PNG, an organized PCD and a JSON file
// with T_cam_model and the intrinsics.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "cli/command.h"
#include "core/error.h"
#include "io/mesh_io.h"
#include "io/png.h"
#include "io_pcl/pcd.h"
#include "models/registry.h"
#include "scenes/views.h"

namespace fs = std::filesystem;

static pb::cli::Command cmd(
    "render-views", "render training views of a model (depth PNG + organized PCD + pose JSON)",
    [](int argc, char** argv) {
      CLI::App app{"Render a model alone from chosen viewpoints: 1 = one side view, 8 = a ring,\n"
                   "12 = the ring plus 4 from below (as the thesis), other N = a Fibonacci sphere.\n"
                   "Writes DIR/view_IIII.{png,pcd,json} and DIR/views.json."};
      std::string model, out, registry;
      pb::ViewSettings vs;
      double depth_scale = 0.1;
      app.add_option("model", model, "registry name (models/models.yaml) or a mesh file (mm)")->required();
      app.add_option("--views", vs.views, "number of views (1, 8, 12 or any N)")->capture_default_str();
      app.add_option("--out", out, "output folder")->required();
      app.add_option("--registry", registry, "model registry file (default: the tree's)");
      app.add_option("--resolution", vs.resolution, "square image size, pixels")->capture_default_str();
      app.add_option("--fov", vs.fov_deg, "field of view, degrees")->capture_default_str();
      app.add_option("--distance-factor", vs.distance_factor, "camera distance / bounding-box diagonal")
          ->capture_default_str();
      app.add_option("--elevation", vs.elevation_deg, "ring elevation, degrees")->capture_default_str();
      app.add_option("--depth-scale", depth_scale, "PNG value * depth_scale = mm")->capture_default_str();
      PB_CLI_PARSE(app, argc, argv);

      if (vs.views < 1 || vs.views > 10000)
        throw pb::InputError("", "--views", "must be in [1, 10000], got " + std::to_string(vs.views));
      if (vs.resolution < 8 || vs.resolution > 8192)
        throw pb::InputError("", "--resolution", "must be in [8, 8192], got " + std::to_string(vs.resolution));
      if (!(vs.fov_deg > 0 && vs.fov_deg < 170)) throw pb::InputError("", "--fov", "must be in (0, 170)");
      if (!(vs.distance_factor > 0)) throw pb::InputError("", "--distance-factor", "must be positive");
      if (!(depth_scale > 0)) throw pb::InputError("", "--depth-scale", "must be positive");

      pb::Mesh mesh;
      std::string name = model;
      const bool is_file = fs::is_regular_file(model);
      if (is_file) {
        mesh = pb::load_mesh(model);
        name = fs::path(model).stem().string();
      } else {
        const pb::ModelRegistry reg =
            registry.empty() ? pb::ModelRegistry::load_default() : pb::ModelRegistry::load(registry);
        mesh = reg.load_model(model);
      }
      const auto views = pb::render_training_views(mesh, vs);
      float zmax = 0;
      for (const auto& v : views)
        for (float z : v.depth.z) zmax = std::max(zmax, z);
      if (zmax > 65535.0 * depth_scale)
        throw pb::InputError("", "--depth-scale",
                             "depth up to " + std::to_string(zmax) + " mm does not fit 16 bits at this scale");

      const fs::path dir(out);
      if (fs::exists(dir) && !fs::is_empty(dir) && !fs::exists(dir / "views.json"))
        throw pb::InputError(out, "--out", "exists and is not a render-views folder; remove it or choose another");
      const fs::path tmp = dir.string() + ".partial";
      std::error_code ec;
      fs::remove_all(tmp, ec);
      try {
        fs::create_directories(tmp);
        nlohmann::ordered_json index;
        index["model"] = name;
        index["source"] = is_file ? fs::path(model).filename().string() : model;
        index["views"] = vs.views;
        index["resolution"] = vs.resolution;
        index["fov_deg"] = vs.fov_deg;
        index["distance_factor"] = vs.distance_factor;
        index["elevation_deg"] = vs.elevation_deg;
        index["depth_scale"] = depth_scale;
        nlohmann::ordered_json list = nlohmann::ordered_json::array();
        for (size_t i = 0; i < views.size(); ++i) {
          const auto& v = views[i];
          char stem[32];
          std::snprintf(stem, sizeof stem, "view_%04zu", i);
          pb::write_depth_png((tmp / (std::string(stem) + ".png")).string(), v.depth, depth_scale);
          pb::write_organized_pcd((tmp / (std::string(stem) + ".pcd")).string(), v.cloud);
          nlohmann::ordered_json j;
          j["view"] = i;
          std::vector<double> T, K;
          const pb::Mat4 M = v.T_cam_model.matrix();
          for (int r = 0; r < 4; ++r)
            for (int c = 0; c < 4; ++c) T.push_back(M(r, c));
          const pb::Mat3 Km = v.K.K();
          for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) K.push_back(Km(r, c));
          j["T_cam_model"] = T;  // 4x4 row-major, mm
          j["cam_K"] = K;        // 3x3 row-major
          j["width"] = v.K.width;
          j["height"] = v.K.height;
          j["depth_scale"] = depth_scale;
          j["depth"] = std::string(stem) + ".png";
          j["cloud"] = std::string(stem) + ".pcd";
          j["points"] = v.cloud.valid_count();
          pb::atomic_write_text((tmp / (std::string(stem) + ".json")).string(), j.dump(2) + "\n");
          list.push_back(j);
        }
        index["list"] = list;
        pb::atomic_write_text((tmp / "views.json").string(), index.dump(2) + "\n");
        if (fs::exists(dir)) {
          const fs::path old = dir.string() + ".old";
          fs::remove_all(old, ec);
          fs::rename(dir, old);
          fs::rename(tmp, dir);
          fs::remove_all(old, ec);
        } else {
          if (dir.has_parent_path()) fs::create_directories(dir.parent_path());
          fs::rename(tmp, dir);
        }
      } catch (const fs::filesystem_error& e) {
        fs::remove_all(tmp, ec);
        throw pb::InputError(out, "--out", std::string("cannot write: ") + e.what());
      } catch (...) {
        fs::remove_all(tmp, ec);
        throw;
      }
      std::printf("rendered %zu views of %s into %s\n", views.size(), name.c_str(), out.c_str());
      return 0;
    });
