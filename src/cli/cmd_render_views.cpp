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
#include "io/folder.h"
#include "io/mesh_io.h"
#include "io/png.h"
#include "io_pcl/pcd.h"
#include "models/registry.h"
#include "scenes/views.h"

namespace fs = std::filesystem;

namespace {

struct RenderViewsArgs {
  std::string model, out, registry;
  pb::ViewSettings vs;
  double depth_scale = 0.1;
};

void check_args(const RenderViewsArgs& a) {
  const pb::ViewSettings& vs = a.vs;
  if (vs.views < 1 || vs.views > 10000)
    throw pb::InputError("", "--views", "must be in [1, 10000], got " + std::to_string(vs.views));
  if (vs.resolution < 8 || vs.resolution > 8192)
    throw pb::InputError("", "--resolution", "must be in [8, 8192], got " + std::to_string(vs.resolution));
  if (!(vs.fov_deg > 0 && vs.fov_deg < 170)) throw pb::InputError("", "--fov", "must be in (0, 170)");
  if (!(vs.distance_factor > 0)) throw pb::InputError("", "--distance-factor", "must be positive");
  if (!(a.depth_scale > 0)) throw pb::InputError("", "--depth-scale", "must be positive");
}

// A mesh file (mm) or a registry model; `name` is the file stem or the model.
pb::Mesh load_model_mesh(const RenderViewsArgs& a, bool is_file, std::string& name) {
  name = a.model;
  if (is_file) {
    name = fs::path(a.model).stem().string();
    return pb::load_mesh(a.model);
  }
  const pb::ModelRegistry reg =
      a.registry.empty() ? pb::ModelRegistry::load_default() : pb::ModelRegistry::load(a.registry);
  return reg.load_model(a.model);
}

std::vector<double> rowmajor(const Eigen::MatrixXd& M) {
  std::vector<double> v;
  for (int r = 0; r < M.rows(); ++r)
    for (int c = 0; c < M.cols(); ++c) v.push_back(M(r, c));
  return v;
}

// Writes view i's PNG, PCD and JSON into `dir`; returns the JSON.
nlohmann::ordered_json write_view(const fs::path& dir, size_t i, const pb::TrainingView& v, double depth_scale) {
  char stem[32];
  std::snprintf(stem, sizeof stem, "view_%04zu", i);
  pb::write_depth_png((dir / (std::string(stem) + ".png")).string(), v.depth, depth_scale);
  pb::write_organized_pcd((dir / (std::string(stem) + ".pcd")).string(), v.cloud);
  nlohmann::ordered_json j;
  j["view"] = i;
  j["T_cam_model"] = rowmajor(v.T_cam_model.matrix());  // 4x4 row-major, mm
  j["cam_K"] = rowmajor(v.K.K());                       // 3x3 row-major
  j["width"] = v.K.width;
  j["height"] = v.K.height;
  j["depth_scale"] = depth_scale;
  j["depth"] = std::string(stem) + ".png";
  j["cloud"] = std::string(stem) + ".pcd";
  j["points"] = v.cloud.valid_count();
  pb::atomic_write_text((dir / (std::string(stem) + ".json")).string(), j.dump(2) + "\n");
  return j;
}

int render_views_main(int argc, char** argv) {
  CLI::App app{"Render a model alone from chosen viewpoints: 1 = one side view, 8 = a ring,\n"
               "12 = the ring plus 4 from below (as the thesis), other N = a Fibonacci sphere.\n"
               "Writes DIR/view_IIII.{png,pcd,json} and DIR/views.json."};
  RenderViewsArgs a;
  pb::ViewSettings& vs = a.vs;
  app.add_option("model", a.model, "registry name (models/models.yaml) or a mesh file (mm)")->required();
  app.add_option("--views", vs.views, "number of views (1, 8, 12 or any N)")->capture_default_str();
  app.add_option("--out", a.out, "output folder")->required();
  app.add_option("--registry", a.registry, "model registry file (default: the tree's)");
  app.add_option("--resolution", vs.resolution, "square image size, pixels")->capture_default_str();
  app.add_option("--fov", vs.fov_deg, "field of view, degrees")->capture_default_str();
  app.add_option("--distance-factor", vs.distance_factor, "camera distance / bounding-box diagonal")
      ->capture_default_str();
  app.add_option("--elevation", vs.elevation_deg, "ring elevation, degrees")->capture_default_str();
  app.add_option("--depth-scale", a.depth_scale, "PNG value * depth_scale = mm")->capture_default_str();
  PB_CLI_PARSE(app, argc, argv);
  check_args(a);

  std::string name;
  const bool is_file = fs::is_regular_file(a.model);
  const pb::Mesh mesh = load_model_mesh(a, is_file, name);
  const auto views = pb::render_training_views(mesh, vs);
  float zmax = 0;
  for (const auto& v : views)
    for (float z : v.depth.z) zmax = std::max(zmax, z);
  if (zmax > 65535.0 * a.depth_scale)
    throw pb::InputError("", "--depth-scale",
                         "depth up to " + std::to_string(zmax) + " mm does not fit 16 bits at this scale");

  const fs::path dir(a.out);
  if (fs::exists(dir) && !fs::is_empty(dir) && !fs::exists(dir / "views.json"))
    throw pb::InputError(a.out, "--out", "exists and is not a render-views folder; remove it or choose another");
  pb::write_folder_atomically(a.out, "cannot write: ", [&](const fs::path& tmp) {
    nlohmann::ordered_json index = {
        {"model", name}, {"source", is_file ? fs::path(a.model).filename().string() : a.model},
        {"views", vs.views}, {"resolution", vs.resolution}, {"fov_deg", vs.fov_deg},
        {"distance_factor", vs.distance_factor}, {"elevation_deg", vs.elevation_deg}, {"depth_scale", a.depth_scale}};
    nlohmann::ordered_json list = nlohmann::ordered_json::array();
    for (size_t i = 0; i < views.size(); ++i) list.push_back(write_view(tmp, i, views[i], a.depth_scale));
    index["list"] = list;
    pb::atomic_write_text((tmp / "views.json").string(), index.dump(2) + "\n");
  });
  std::printf("rendered %zu views of %s into %s\n", views.size(), name.c_str(), a.out.c_str());
  return 0;
}

}  // namespace

static pb::cli::Command cmd("render-views", "render training views of a model (depth PNG + organized PCD + pose JSON)",
                            render_views_main);
