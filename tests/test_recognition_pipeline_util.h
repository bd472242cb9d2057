// Small rendered table scenes for the recognition pipeline tests: an
// asymmetric L-shaped block (plus an optional distractor) standing on a
// table, seen from above at an angle, with seeded Gaussian depth noise.
#pragma once

#include <cmath>
#include <vector>

#include "core/random.h"
#include "core/types.h"
#include "models/procedural.h"
#include "render/renderer.h"

namespace pbtest {

// An L-shaped block (no symmetry): a 120 x 60 x 40 mm base with a
// 40 x 60 x 100 mm post on one end and a 30 mm cube sticking out sideways,
// origin at the bounding box centre.
inline pb::Mesh make_l_block() {
  pb::Mesh base = pb::make_box(120, 60, 40);
  pb::Mesh post = pb::make_box(40, 60, 100);
  pb::Pose T;
  T.t = pb::Vec3(40, 0, 50);
  post.transform(T);
  pb::Mesh nub = pb::make_box(30, 30, 30);
  T.t = pb::Vec3(-30, 45, 0);
  nub.transform(T);
  pb::Mesh m = base;
  m.append(post);
  m.append(nub);
  const Eigen::AlignedBox3f b = m.bounds();
  pb::Pose C;
  C.t = -b.center().cast<double>();
  m.transform(C);
  m.compute_vertex_normals();
  return m;
}

// Camera looking at `target` (world, z up) from `distance` mm at `elevation`
// degrees above the horizontal and `azimuth` degrees around z.
inline pb::Pose look_at(const pb::Vec3& target, double distance, double elevation_deg, double azimuth_deg) {
  const double el = elevation_deg * M_PI / 180, az = azimuth_deg * M_PI / 180;
  const pb::Vec3 c = target + distance * pb::Vec3(std::cos(el) * std::sin(az), -std::cos(el) * std::cos(az),
                                                  std::sin(el));
  const pb::Vec3 z = (target - c).normalized();
  const pb::Vec3 x = z.cross(pb::Vec3::UnitZ()).normalized();
  const pb::Vec3 y = z.cross(x);
  pb::Pose T_world_cam;
  T_world_cam.R.col(0) = x;
  T_world_cam.R.col(1) = y;
  T_world_cam.R.col(2) = z;
  T_world_cam.t = c;
  return T_world_cam;
}

struct TableScene {
  pb::Intrinsics K;
  pb::DepthImage depth;
  pb::Pose T_cam_model;  // ground truth of the object (if present)
};

struct TableSceneOptions {
  bool object = true;        // the L-block on the table
  bool distractor = false;   // a cylinder beside it
  bool table = true;
  double yaw_deg = 30;       // object yaw on the table
  double azimuth_deg = 20;   // camera azimuth
  double elevation_deg = 40;
  double distance_mm = 700;
  double noise_mm = 1.0;
  uint64_t seed = 7;
  int width = 320, height = 240;
};

inline TableScene render_table_scene(const pb::Mesh& object, const TableSceneOptions& o = {}) {
  TableScene s;
  s.K = pb::Intrinsics::from_fov(o.width, o.height, 50.0, 50.0 * o.height / o.width);
  const pb::Pose T_cam_world = look_at(pb::Vec3(0, 0, 40), o.distance_mm, o.elevation_deg, o.azimuth_deg).inverse();
  const pb::Mesh table = pb::make_box(2000, 2000, 20);
  pb::Pose T_world_table;
  T_world_table.t = pb::Vec3(0, 0, -10);
  const Eigen::AlignedBox3f b = object.bounds();
  pb::Pose T_world_model;
  const double yaw = o.yaw_deg * M_PI / 180;
  T_world_model.R = Eigen::AngleAxisd(yaw, pb::Vec3::UnitZ()).toRotationMatrix();
  T_world_model.t = pb::Vec3(0, 0, -b.min().z());
  s.T_cam_model = T_cam_world * T_world_model;
  const pb::Mesh cyl = pb::make_cylinder(30, 80);
  pb::Pose T_world_cyl;
  T_world_cyl.t = pb::Vec3(-150, 60, 40);
  std::vector<pb::RenderItem> items;
  if (o.table) items.push_back({&table, T_cam_world * T_world_table, 0});
  if (o.object) items.push_back({&object, s.T_cam_model, 1});
  if (o.distractor) items.push_back({&cyl, T_cam_world * T_world_cyl, 2});
  pb::DepthRenderer r(s.K);
  s.depth = r.render(items).depth;
  pb::Rng rng(o.seed);
  for (float& z : s.depth.z)
    if (z > 0) z += static_cast<float>(rng.normal(0.0, o.noise_mm));
  return s;
}

// Rotation angle between two rotations, degrees.
inline double angle_deg(const pb::Mat3& a, const pb::Mat3& b) {
  const double c = std::clamp(((a.transpose() * b).trace() - 1) / 2, -1.0, 1.0);
  return std::acos(c) * 180 / M_PI;
}

}  // namespace pbtest
