// Clouds for the tests of the pair-feature kernels that work eight pairs at a
// time (test_recognition_ppf_keys.cpp, test_recognition_local_fpfh_pairs.cpp):
// random oriented points, the cases a lane must leave to the one-at-a-time
// path, and pairs whose atan2 angle lies at given bin edges.
#pragma once

#include <cmath>
#include <limits>
#include <vector>

#include "core/random.h"
#include "core/types.h"
#include "recognition/cloud.h"

namespace pb::pair_clouds {

inline Vec3f unit(Rng& rng) {
  return Vec3f(static_cast<float>(rng.normal()), static_cast<float>(rng.normal()), static_cast<float>(rng.normal()))
      .normalized();
}

// 203 points in a cube of half-edge `scale` (so the last block of eight is
// short), random unit normals.
inline PointSet random_cloud(Rng& rng, float scale) {
  PointSet cloud;
  for (int k = 0; k < 203; ++k) {
    cloud.points.emplace_back(static_cast<float>(rng.uniform(-scale, scale)),
                              static_cast<float>(rng.uniform(-scale, scale)),
                              static_cast<float>(rng.uniform(-scale, scale)));
    cloud.normals.push_back(unit(rng));
  }
  return cloud;
}

// Points on a plane with its normal either way (every cosine to a line in
// the plane 0, so equal), on a line with normals along it (a degenerate
// frame), duplicates of earlier points, and non-finite or zero values. *n0
// (if given) gets the plane's normal.
inline PointSet special_cloud(Rng& rng, float scale, Vec3f* n0_out = nullptr) {
  PointSet special;
  const Vec3f n0 = unit(rng), a = n0.unitOrthogonal(), b = n0.cross(a);
  if (n0_out) *n0_out = n0;
  for (int k = 0; k < 40; ++k) {
    special.points.push_back(scale * (static_cast<float>(rng.uniform(-1, 1)) * a +
                                      static_cast<float>(rng.uniform(-1, 1)) * b));
    special.normals.push_back(k % 2 ? n0 : Vec3f(-n0));
  }
  for (int k = 0; k < 10; ++k) {
    special.points.push_back(scale * static_cast<float>(k) * 0.1f * n0);
    special.normals.push_back(n0);
  }
  for (int k = 0; k < 6; ++k) {
    special.points.push_back(special.points[static_cast<size_t>(k)]);
    special.normals.push_back(unit(rng));
  }
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  special.points.emplace_back(nan, 0.f, 0.f);
  special.normals.push_back(n0);
  special.points.emplace_back(scale, scale, scale);
  special.normals.emplace_back(nan, nan, nan);
  special.points.emplace_back(inf, 0.f, scale);
  special.normals.push_back(n0);
  special.points.emplace_back(0.f, 0.f, 0.f);
  special.normals.emplace_back(0.f, 0.f, 0.f);
  return special;
}

// Pairs whose f1 = atan2(y, x) lies at the given angles and a few floats
// either side: a point at the origin with its normal leaned by e from +x
// toward +z and a partner on the z axis whose normal lies in the xy plane
// give f1 = -e or e (the first point the source, the partner's normal
// perpendicular to the line), for each e of `edges`.
inline PointSet edge_cloud(Rng& rng, float scale, const std::vector<float>& edges) {
  PointSet cloud;
  for (const float e : edges)
    for (int u = -3; u <= 3; ++u) {
      const float t = std::nextafter(e, u < 0 ? -10.f : 10.f) + static_cast<float>(u) * 1e-7f;
      cloud.points.emplace_back(0.f, 0.f, 0.f);
      cloud.normals.emplace_back(std::cos(t), 0.f, std::sin(t));
    }
  for (int k = 0; k < 8; ++k) {
    const float t = static_cast<float>(rng.uniform(-1.5, 1.5));
    cloud.points.emplace_back(0.f, 0.f, 0.7f * scale);
    cloud.normals.emplace_back(std::cos(t), std::sin(t), 0.f);
  }
  return cloud;
}

}  // namespace pb::pair_clouds
