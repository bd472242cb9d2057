#include "scenes/views.h"

#include <cmath>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/rotation.h"
#include "io/cloud.h"
#include "models/registry.h"
#include "render/renderer.h"

namespace pb {

namespace {

Vec3 direction(double azimuth_deg, double elevation_deg) {
  const double a = azimuth_deg * M_PI / 180.0, e = elevation_deg * M_PI / 180.0;
  return {std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e)};
}

}  // namespace

std::vector<Vec3> view_directions(const ViewSettings& s) {
  if (s.views < 1) throw InputError("", "views", "must be at least 1, got " + std::to_string(s.views));
  std::vector<Vec3> dirs;
  if (s.views == 1) {
    dirs.push_back(direction(-90.0, s.side_elevation_deg));  // from -y, the model's front
  } else if (s.views == 8 || s.views == 12) {
    for (int k = 0; k < 8; ++k) dirs.push_back(direction(45.0 * k, s.elevation_deg));
    if (s.views == 12)
      for (int k = 0; k < 4; ++k) dirs.push_back(direction(45.0 + 90.0 * k, s.below_elevation_deg));
  } else {
    // Fibonacci sphere: z evenly spaced, golden-angle azimuth steps.
    const double golden = M_PI * (3.0 - std::sqrt(5.0));
    for (int k = 0; k < s.views; ++k) {
      const double z = 1.0 - (2.0 * k + 1.0) / s.views;
      const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
      dirs.emplace_back(r * std::cos(golden * k), r * std::sin(golden * k), z);
    }
  }
  return dirs;
}

double scene_set_elevation_deg(const std::string& dataset_root) {
  const std::string path = (std::filesystem::path(dataset_root) / "posebench_scene.json").string();
  const std::string field = "settings.camera.elevation_deg";
  std::ifstream in(path);
  if (!in)
    throw InputError(path, "views.follow_scene",
                     "needs a scene set made by `posebench generate` (its posebench_scene.json), and there is none");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path, "", std::string("malformed JSON: ") + e.what());
  }
  const nlohmann::json* e = &j;
  for (const char* k : {"settings", "camera", "elevation_deg"}) {
    if (!e->is_object() || !e->contains(k)) throw InputError(path, field, "missing (needed by views.follow_scene)");
    e = &(*e)[k];
  }
  if (!e->is_array() || e->size() != 2 || !(*e)[0].is_number() || !(*e)[1].is_number())
    throw InputError(path, field, "must be [low, high] in degrees, got " + e->dump());
  const double lo = (*e)[0].get<double>(), hi = (*e)[1].get<double>();
  if (!(lo >= -90 && hi <= 90 && lo <= hi))
    throw InputError(path, field, "must be [low, high] within [-90, 90], got " + e->dump());
  return 0.5 * (lo + hi);
}

ViewSettings views_at_elevation(const ViewSettings& settings, double elevation_deg) {
  ViewSettings out = settings;
  out.elevation_deg = out.side_elevation_deg = elevation_deg;
  out.follow_scene = false;
  return out;
}

ViewSettings views_for_scene_set(const ViewSettings& settings, const std::string& dataset_root) {
  return settings.follow_scene ? views_at_elevation(settings, scene_set_elevation_deg(dataset_root)) : settings;
}

std::vector<TrainingView> render_training_views(const Mesh& mesh, const ViewSettings& s) {
  if (mesh.empty()) throw InputError("", "mesh", "empty mesh");
  if (s.resolution < 8 || s.resolution > 8192)
    throw InputError("", "resolution", "must be in [8, 8192], got " + std::to_string(s.resolution));
  if (!(s.fov_deg > 0 && s.fov_deg < 170))
    throw InputError("", "fov_deg", "must be in (0, 170), got " + std::to_string(s.fov_deg));
  if (!(s.distance_factor > 0))
    throw InputError("", "distance_factor", "must be positive, got " + std::to_string(s.distance_factor));
  const auto dirs = view_directions(s);
  // The camera looks at the model origin (the bounding box centre of a
  // registry model); distance from the bounding box diagonal so that the
  // whole model is in view for distance_factor >= ~1.5.
  double diameter = mesh.bounds().diagonal().norm();
  if (!(diameter > 0)) throw InputError("", "mesh", "degenerate mesh");
  const double dist = s.distance_factor * diameter;
  const Intrinsics K = Intrinsics::from_fov(s.resolution, s.resolution, s.fov_deg, s.fov_deg);
  RenderSettings rs;
  rs.near_mm = std::max(1.0, 0.1 * (dist - diameter));
  rs.far_mm = dist + 2 * diameter;
  DepthRenderer renderer(K, rs);
  std::vector<TrainingView> views;
  for (const Vec3& d : dirs) {
    const Pose T_world_cam = look_at(d * dist, Vec3::Zero(), Vec3::UnitZ());
    TrainingView v;
    v.K = K;
    v.T_cam_model = T_world_cam.inverse();
    const RenderOutput out = renderer.render({RenderItem{&mesh, v.T_cam_model, 0}});
    v.depth = out.depth;
    v.cloud = OrganizedCloud::from_depth(v.depth, K);
    views.push_back(std::move(v));
  }
  return views;
}

TrainingViews training_views(const Mesh& mesh, const ViewSettings& settings, const std::string& model_name) {
  TrainingViews t;
  t.model_name = model_name;
  if (mesh.empty()) {
    t.empty_reason = "model '" + model_name + "' has no triangles";
  } else if (!(mesh.bounds().diagonal().norm() > 0) || !mesh.bounds().diagonal().allFinite()) {
    t.empty_reason = "model '" + model_name + "' is degenerate (zero or non-finite extent)";
  } else {
    t.views = render_training_views(mesh, settings);
    t.diameter_mm = exact_diameter(mesh);
  }
  return t;
}

Pose cloud_model_pose(const std::vector<Vec3f>& points_cam) {
  Eigen::AlignedBox3f box;
  for (const Vec3f& p : points_cam)
    if (p.allFinite()) box.extend(p);
  Pose T;
  if (!box.isEmpty()) T.t = box.center().cast<double>();
  return T;
}

TrainingViews cloud_training_views(const std::vector<Vec3f>& points_cam, const std::string& model_name) {
  TrainingViews t;
  t.model_name = model_name;
  PointCloudFile c;
  c.points = points_cam;
  c.width = static_cast<int>(points_cam.size());
  size_t in_front = 0;
  for (const Vec3f& p : points_cam) in_front += p.allFinite() && p.z() > 0;
  if (in_front < 3) {
    t.empty_reason = "model '" + model_name + "': fewer than 3 points in front of the camera (z > 0)";
    return t;
  }
  TrainingView v;
  v.K = virtual_camera(c, model_name);
  v.T_cam_model = cloud_model_pose(points_cam);
  v.depth = project_cloud(c, v.K);
  v.cloud = OrganizedCloud::from_depth(v.depth, v.K);
  t.views.push_back(std::move(v));
  return t;
}

}  // namespace pb
