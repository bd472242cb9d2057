// The layout steps of a scene generator attempt (generator_internal.h):
// target, camera, background, occluder footprint and other objects. Each
// step draws from the attempt's random stream in a fixed order.
#include <algorithm>
#include <cmath>
#include <utility>

#include "core/rotation.h"
#include "scenes/generator_internal.h"

namespace pb {

using namespace scene_detail;

// 1. Target at the origin.
void SceneGenerator::Impl::place_target(Rng& rng, Layout& L) const {
  if (s.target_free_probability > 0 && rng.uniform() < s.target_free_probability) {
    const Mat3 R = random_rotation(rng);  // uniform: yaw included
    L.objs.push_back(on_ground_rotated(target, R, Vec2::Zero()));
    return;
  }
  const int ri = sample_rest_pose(rest[target], s.target_upright_probability, rng);
  const double yaw = rng.uniform(0, 2 * M_PI);
  Placed p = on_ground(target, ri, yaw, Vec2::Zero());
  if (s.target_tilt_deg > 0) {  // the rest pose leaned about a horizontal axis, on its lowest point
    const double axis_az = rng.uniform(0, 2 * M_PI);
    const double tilt = rng.uniform(0, s.target_tilt_deg) * M_PI / 180.0;
    p = on_ground_rotated(target, axis_angle(Vec3(std::cos(axis_az), std::sin(axis_az), 0), tilt) * p.T_world_model.R,
                          Vec2::Zero());
  }
  L.objs.push_back(std::move(p));
}

// 2. Camera: distance, elevation and azimuth, looking at the target's centre
// shifted in the image plane by up to look_jitter of the half view.
bool SceneGenerator::Impl::place_camera(Rng& rng, Layout& L, GeneratedImage& img, std::string& why) const {
  const Placed& tgt = L.target();
  const double dist = rng.uniform(s.camera.distance_mm.lo, s.camera.distance_mm.hi);
  const double elev = rng.uniform(s.camera.elevation_deg.lo, s.camera.elevation_deg.hi) * M_PI / 180.0;
  const double az = rng.uniform(0, 2 * M_PI);
  const Vec3 look(0, 0, 0.5 * tgt.height);
  const Vec3 eye0 = look + dist * Vec3(std::cos(elev) * std::cos(az), std::cos(elev) * std::sin(az), std::sin(elev));
  Pose T_world_cam = look_at(eye0, look, Vec3::UnitZ());
  const double jitter = s.camera.look_jitter * dist * std::tan(half_fov_min());
  T_world_cam.t += rng.uniform(-jitter, jitter) * T_world_cam.R.col(0) +
                   rng.uniform(-jitter, jitter) * T_world_cam.R.col(1);
  L.dist = dist;
  L.eye = T_world_cam.t;
  L.T_world_cam = T_world_cam;
  L.T_cam_world = T_world_cam.inverse();
  img.camera_distance_mm = dist;
  img.camera_elevation_deg = elev * 180.0 / M_PI;
  img.camera_azimuth_deg = az * 180.0 / M_PI;
  img.T_world_cam = T_world_cam;
  if (L.eye.z() <= 0) {
    why = "camera below the ground";
    return false;
  }
  // Ground direction towards the camera and its perpendicular.
  Vec2 g(L.eye.x(), L.eye.y());
  if (g.norm() < 1e-6) g = Vec2(std::cos(az), std::sin(az));
  g.normalize();
  L.g = g;
  L.perp = Vec2(-g.y(), g.x());
  L.r_t = 0;
  for (const auto& q : tgt.footprint) L.r_t = std::max(L.r_t, q.norm());
  return true;
}

// A wall facing the camera (normal L.wall_n, horizontal) whose face passes
// through L.wall_point, from height `bottom` up.
Placed SceneGenerator::Impl::wall_at(const Layout& L, double bottom) const {
  const WarehouseSettings& w = s.warehouse;
  Placed wall;
  wall.mesh = &wall_mesh;
  const double yaw = std::atan2(L.wall_n.y(), L.wall_n.x()) - M_PI / 2;  // box y axis along wall_n
  wall.T_world_model.R = axis_angle(Vec3::UnitZ(), yaw);
  const Vec2 c = L.wall_point - L.wall_n * (0.5 * w.wall_thickness_mm);
  wall.T_world_model.t = Vec3(c.x(), c.y(), bottom + 0.5 * w.wall_height_mm);
  return wall;
}

// 3. Table under everything, and (table.floor_drop_mm, wall_distance_mm) a
// room around it: a floor below and a wall behind the table as seen from
// the camera; warehouse: a floor and (warehouse.wall) a wall behind the
// target. Only a room's wall draws from the stream (default sets keep their
// images).
void SceneGenerator::Impl::place_background(Rng& rng, Layout& L) const {
  L.wall_point = Vec2::Zero();
  L.wall_n = L.g;
  if (!warehouse()) {
    const TableSettings& t = s.table;
    Placed table;
    table.mesh = &table_mesh;
    table.T_world_model.t = Vec3(0, 0, -0.5 * t.thickness_mm);
    L.bg.push_back(table);
    if (t.floor_drop_mm > 0) {
      Placed floor;
      floor.mesh = &floor_mesh;
      floor.T_world_model.t = Vec3(0, 0, -t.floor_drop_mm - 0.5 * s.warehouse.floor_thickness_mm);
      L.bg.push_back(floor);
    }
    if (t.wall_distance_mm.hi > 0) {
      double far = 0;  // the table's farthest corner from the target, away from the camera
      for (const double x : {-0.5, 0.5})
        for (const double y : {-0.5, 0.5}) far = std::max(far, -L.g.dot(Vec2(x, y) * t.size_mm));
      L.wall_point = -L.g * (far + rng.uniform(t.wall_distance_mm.lo, t.wall_distance_mm.hi));
      L.bg.push_back(wall_at(L, -t.floor_drop_mm));
    }
    return;
  }
  const WarehouseSettings& w = s.warehouse;
  const double wd = L.r_t + rng.uniform(w.wall_distance_mm.lo, w.wall_distance_mm.hi);
  const double wyaw = rng.uniform(-w.wall_yaw_deg, w.wall_yaw_deg) * M_PI / 180.0;
  L.wall_n = Eigen::Rotation2Dd(wyaw) * L.g;
  L.wall_point = -L.g * wd;
  Placed floor;
  floor.mesh = &floor_mesh;
  floor.T_world_model.t = Vec3(0, 0, -0.5 * w.floor_thickness_mm);
  L.bg.push_back(floor);
  if (!w.wall) return;  // the floor alone (on_ground_area: no wall bounds it)
  L.bg.push_back(wall_at(L, 0.0));
}

bool SceneGenerator::Impl::on_ground_area(const Layout& L, const Vec2& q, double table_margin) const {
  if (warehouse()) return !s.warehouse.wall || !((q - L.wall_point).dot(L.wall_n) < gap());
  return !(std::abs(q.x()) > 0.5 * s.table.size_mm - table_margin ||
           std::abs(q.y()) > 0.5 * s.table.size_mm - table_margin);
}

bool SceneGenerator::Impl::fits(const Layout& L, const Placed& p, const std::vector<const Placed*>& others) const {
  const double gap = this->gap();
  for (const auto& q : p.footprint)
    if (!on_ground_area(L, q, gap)) return false;
  for (const Placed* o : others)
    if (convex_polygons_overlap(p.footprint, o->footprint, gap)) return false;
  return clear_of_camera(L, p);
}

bool SceneGenerator::Impl::clear_of_camera(const Layout& L, const Placed& p) const {
  const Vec3 centre = p.T_world_model.t + p.T_world_model.R * Vec3::Zero();
  if ((L.T_cam_world * centre).z() - p.radius < rset.near_mm + s.camera.depth_clearance_mm) return false;
  if ((centre - L.eye).norm() < p.radius + rset.near_mm + s.camera.clearance_mm) return false;
  return true;
}

// 4. Occluder footprint between camera and target (occluded images only);
// its height is searched once everything is placed.
bool SceneGenerator::Impl::place_occluder(Rng& rng, Layout& L, std::string& why) const {
  const OcclusionSettings& o = s.occlusion;
  Occluder& oc = L.occl;
  oc.on = o.enabled && rng.bernoulli(o.probability);
  oc.goal = oc.on ? rng.uniform(o.visib_fract.lo, o.visib_fract.hi) : 0.0;
  if (!oc.on) return true;
  const double r_t = L.r_t;
  oc.box = rng.bernoulli(o.box_probability);
  double half_depth;
  if (oc.box) {
    oc.w = rng.uniform(o.box_width.lo, o.box_width.hi) * 2 * r_t;
    oc.d = rng.uniform(o.box_depth_mm.lo, o.box_depth_mm.hi);
    half_depth = 0.5 * oc.d;
  } else {
    oc.r = std::max(o.cylinder_min_radius_mm, rng.uniform(o.cylinder_radius.lo, o.cylinder_radius.hi) * r_t);
    half_depth = oc.r;
  }
  const double lateral = rng.uniform(o.lateral_offset.lo, o.lateral_offset.hi) * r_t;
  const double along = r_t + half_depth + gap() + rng.uniform(o.extra_distance.lo, o.extra_distance.hi) * r_t;
  const Vec2 c = L.g * along + L.perp * lateral;
  const double yaw = std::atan2(L.perp.y(), L.perp.x());  // box x axis (width) along perp
  Polygon local;
  if (oc.box) {
    local = {{-oc.w / 2, -oc.d / 2}, {oc.w / 2, -oc.d / 2}, {oc.w / 2, oc.d / 2}, {-oc.w / 2, oc.d / 2}};
  } else {
    const int n = o.footprint_sides;
    for (int k = 0; k < n; ++k)
      local.emplace_back(oc.r * std::cos(2 * M_PI * k / n), oc.r * std::sin(2 * M_PI * k / n));
  }
  oc.placed.footprint = transform_footprint(local, yaw, c);
  oc.placed.T_world_model.R = axis_angle(Vec3::UnitZ(), yaw);
  oc.placed.T_world_model.t = Vec3(c.x(), c.y(), 0);
  // Height hiding the whole target (line from the eye over the target's
  // top, at the occluder's far side), with a margin; below the camera.
  const Vec3& eye = L.eye;
  const double tgt_h = L.target().height;
  const double D = Vec2(eye.x(), eye.y()).norm();
  const double x = std::max(0.0, along - half_depth);
  double h = tgt_h + (eye.z() - tgt_h) * std::min(1.0, x / std::max(D, 1e-6));
  oc.hmax = std::min(o.height_factor * h + o.height_margin_mm, eye.z() - o.camera_headroom_mm);
  if (oc.hmax <= o.min_height_mm) {
    why = "no room for an occluder";
    return false;
  }
  oc.placed.radius = std::sqrt(std::pow(oc.box ? 0.5 * std::hypot(oc.w, oc.d) : oc.r, 2) + oc.hmax * oc.hmax);
  // Camera clearance for the tallest occluder.
  if ((Vec3(c.x(), c.y(), 0.5 * oc.hmax) - eye).norm() < oc.placed.radius + rset.near_mm + s.camera.clearance_mm) {
    why = "occluder too close to the camera";
    return false;
  }
  for (const auto& q : oc.placed.footprint)
    if (!on_ground_area(L, q, 0.0)) {
      why = "occluder does not fit";
      return false;
    }
  return true;
}

// 5. Other objects, scattered around the target (a disc as wide as the view
// at the target's distance) with their origin inside the image.
bool SceneGenerator::Impl::place_distractors(Rng& rng, Layout& L, std::string& why) const {
  const DistractorSettings& ds = s.distractors;
  double spread = std::max(ds.spread_min_radii * L.r_t, L.dist * std::tan(half_fov_min()));
  if (ds.spread_max_radii > 0) spread = std::min(spread, ds.spread_max_radii * L.r_t);
  const int n_other = pool.empty() ? 0 : rng.uniform_int(ds.min_count, ds.max_count);
  const double m = ds.image_margin;
  for (int k = 0; k < n_other; ++k) {
    const int mi = pool[rng.uniform_int(0, static_cast<int>(pool.size()) - 1)];
    const int ri = sample_rest_pose(rest[mi], ds.upright_probability, rng);
    const std::vector<const Placed*> others = L.standing();
    bool ok = false;
    for (int tries = 0; tries < ds.placement_tries && !ok; ++tries) {
      const double r = spread * std::sqrt(rng.uniform());
      const double phi = rng.uniform(0, 2 * M_PI);
      const double yaw = rng.uniform(0, 2 * M_PI);
      Placed p = on_ground(mi, ri, yaw, Vec2(r * std::cos(phi), r * std::sin(phi)));
      const Vec3 c = L.T_cam_world * (p.T_world_model.t + Vec3(0, 0, 0));
      if (c.z() <= rset.near_mm) continue;
      const auto uv = K.project(c);
      if (uv.x() < -m * K.width || uv.x() > (1 + m) * K.width || uv.y() < -m * K.height ||
          uv.y() > (1 + m) * K.height)
        continue;
      if (!fits(L, p, others)) continue;
      L.objs.push_back(std::move(p));
      ok = true;
    }
    if (!ok) {
      why = "could not place " + std::to_string(n_other) + " other objects";
      return false;
    }
  }
  return true;
}

}  // namespace pb
