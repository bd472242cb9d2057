// Helpers of the global pipeline tests: an asymmetric object, rendered views
// of it at known poses over no table, preprocessed like the pipeline does.
#pragma once

#include <cmath>
#include <vector>

#include "core/random.h"
#include "core/rotation.h"
#include "core/types.h"
#include "models/procedural.h"
#include "recognition/method.h"
#include "recognition/pipeline.h"
#include "recognition/preprocess/preprocess.h"
#include "render/renderer.h"
#include "scenes/views.h"

namespace pb::testing_global {

// An asymmetric assembly (mm, up +z, origin at its bounding box centre): a
// 140 x 90 x 30 base, a 35 x 35 x 110 tower on one corner, a 70 x 25 x 25
// bar and a lying cylinder on the base. Flat faces and one curved surface;
// no rotational symmetry.
inline Mesh asymmetric_object() {
  auto placed = [](Mesh m, const Vec3& t, const Mat3& R = Mat3::Identity()) {
    Pose T;
    T.R = R;
    T.t = t;
    m.transform(T);
    return m;
  };
  Mesh m = placed(make_box(140, 90, 30), {0, 0, 15});
  m.append(placed(make_box(35, 35, 110), {-45, -20, 30 + 55}));
  m.append(placed(make_box(70, 25, 25), {30, 28, 30 + 12.5}));
  // make_cylinder stands on z = 0 along +z: lay it along x.
  m.append(placed(make_cylinder(14, 60), {10, -30, 30 + 14}, axis_angle(Vec3::UnitY(), M_PI / 2)));
  const Eigen::AlignedBox3f b = m.bounds();
  Pose centre;
  centre.t = -b.center().cast<double>();
  m.transform(centre);
  m.compute_vertex_normals();
  return m;
}

// The synthetic sensor of the thesis (512 x 512, 30 x 30 degrees).
inline Intrinsics synthetic_camera() { return Intrinsics::from_fov(512, 512, 30, 30); }

// T_cam_model of a camera at `distance` from the object's origin, seeing it
// from azimuth / elevation (degrees, model frame, z up), rolled about its
// optical axis by roll_deg.
inline Pose camera_pose(double azimuth_deg, double elevation_deg, double roll_deg, double distance) {
  const double a = azimuth_deg * M_PI / 180, e = elevation_deg * M_PI / 180;
  const Vec3 eye = distance * Vec3(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e));
  const Pose T_model_cam = look_at(eye, Vec3::Zero(), Vec3::UnitZ());
  Pose roll;
  roll.R = axis_angle(Vec3::UnitZ(), roll_deg * M_PI / 180);
  return roll * T_model_cam.inverse();
}

// Renders the mesh alone at T_cam_model, adds Gaussian depth noise (sigma in
// mm, 0 for none) and returns the organized cloud.
inline OrganizedCloud render_cloud(const Mesh& mesh, const Pose& T_cam_model, const Intrinsics& K, double sigma,
                                   uint64_t seed) {
  DepthRenderer r(K);
  RenderOutput out = r.render({RenderItem{&mesh, T_cam_model, 1}});
  Rng rng(seed);
  if (sigma > 0)
    for (float& z : out.depth.z)
      if (z > 0) z += static_cast<float>(rng.normal(0, sigma));
  return OrganizedCloud::from_depth(out.depth, K);
}

// The pipeline's training views: rendered, preprocessed (preprocess_view).
inline std::vector<ViewData> training_views(const Mesh& mesh, const RecognitionSettings& s) {
  std::vector<ViewData> views;
  const auto rendered = render_training_views(mesh, s.views);
  for (size_t i = 0; i < rendered.size(); ++i) {
    ViewData v;
    v.cloud = preprocess_view(rendered[i].cloud, s.preprocess, derive_seed(s.seed, {77, i}));
    v.T_cam_model = rendered[i].T_cam_model;
    if (v.cloud.size() >= 10) views.push_back(std::move(v));
  }
  return views;
}

// Thesis errors: translation (mm) and 1 - |p.q|.
inline double translation_error(const Pose& a, const Pose& b) { return (a.t - b.t).norm(); }
inline double rotation_error(const Pose& a, const Pose& b) {
  return 1.0 - std::abs(to_quaternion(a.R).dot(to_quaternion(b.R)));
}
inline bool correct(const Pose& est, const Pose& gt, double max_t_mm = 50.0, double max_r = 0.05) {
  return translation_error(est, gt) < max_t_mm && rotation_error(est, gt) < max_r;
}

}  // namespace pb::testing_global
