// Shared helpers of the render tests: simple meshes and analytic geometry.
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <limits>

#include "core/types.h"

namespace pbtest {

// A square of half-size s in the model's z = 0 plane, two triangles, normal +z.
inline pb::Mesh make_quad(float s) {
  pb::Mesh m;
  m.vertices = {{-s, -s, 0}, {s, -s, 0}, {s, s, 0}, {-s, s, 0}};
  m.faces = {{0, 1, 2}, {0, 2, 3}};
  return m;
}

// An axis-aligned box centred at the origin with half extents (a, b, c),
// 12 triangles, counter-clockwise seen from outside.
inline pb::Mesh make_box(float a, float b, float c) {
  pb::Mesh m;
  for (int i = 0; i < 8; ++i)
    m.vertices.push_back({(i & 1) ? a : -a, (i & 2) ? b : -b, (i & 4) ? c : -c});
  // faces as quads (outward normals): -x, +x, -y, +y, -z, +z
  const int q[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& f : q) {
    m.faces.push_back({f[0], f[1], f[2]});
    m.faces.push_back({f[0], f[2], f[3]});
  }
  return m;
}

// Ray-box (slab) intersection in the box's frame; returns the entry distance
// t along dir (origin o) or +inf for a miss.
inline double ray_box(const pb::Vec3& o, const pb::Vec3& dir, const pb::Vec3& half) {
  double t0 = -std::numeric_limits<double>::infinity(), t1 = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) {
    if (std::abs(dir[k]) < 1e-15) {
      if (std::abs(o[k]) > half[k]) return std::numeric_limits<double>::infinity();
      continue;
    }
    double a = (-half[k] - o[k]) / dir[k], b = (half[k] - o[k]) / dir[k];
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
  }
  if (t0 > t1 || t1 <= 0) return std::numeric_limits<double>::infinity();
  return t0 > 0 ? t0 : std::numeric_limits<double>::infinity();
}

// Depth (camera z) of the box with half extents `half` at T_cam_box seen
// through pixel (u, v), or +inf.
inline double box_depth(const pb::Intrinsics& K, const pb::Pose& T_cam_box, const pb::Vec3& half,
                        double u, double v) {
  const pb::Vec3 ray((u - K.cx) / K.fx, (v - K.cy) / K.fy, 1.0);  // z = 1
  const pb::Pose T_box_cam = T_cam_box.inverse();
  const pb::Vec3 o = T_box_cam.t;
  const pb::Vec3 d = T_box_cam.R * ray;
  return ray_box(o, d, half);  // t along a ray with z = 1 is the depth
}

// Depth of the plane {p : n.p = d} (camera frame) through pixel (u, v).
inline double plane_depth(const pb::Intrinsics& K, const pb::Vec3& n, double d, double u, double v) {
  const pb::Vec3 ray((u - K.cx) / K.fx, (v - K.cy) / K.fy, 1.0);
  return d / n.dot(ray);
}

}  // namespace pbtest
