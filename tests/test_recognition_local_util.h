// Shared fixtures of the local-descriptor tests (FPFH, SHOT, BOARD frames
// against PCL's): a noisy curved surface and evenly spaced keypoints.
#pragma once

#include <cmath>
#include <vector>

#include "core/random.h"
#include "recognition/cloud.h"

namespace pb::localtest {

// z = 600 + bumps, samples jittered around a 4 mm grid over [-80, 80]^2 (so
// no pair sits exactly on a radius or bin boundary by construction), normals
// from the analytic gradient plus noise, oriented toward the camera.
inline PointSet noisy_surface(uint64_t seed) {
  Rng rng(seed);
  PointSet c;
  for (double y = -80; y <= 80; y += 4)
    for (double x = -80; x <= 80; x += 4) {
      const double px = x + rng.uniform(-1, 1), py = y + rng.uniform(-1, 1);
      const double g1 = 30 * std::exp(-((px - 20) * (px - 20) + (py + 10) * (py + 10)) / (2 * 25.0 * 25.0));
      const double g2 = -15 * std::exp(-((px + 30) * (px + 30) + (py - 30) * (py - 30)) / (2 * 15.0 * 15.0));
      const double h = 600 + 0.1 * px - g1 - g2;
      const double hx = 0.1 + g1 * (px - 20) / 625.0 + g2 * (px + 30) / 225.0;
      const double hy = g1 * (py + 10) / 625.0 + g2 * (py - 30) / 225.0;
      const Vec3 n = (Vec3(hx, hy, -1).normalized() + Vec3(rng.normal(0, 0.02), rng.normal(0, 0.02), 0)).normalized();
      c.points.emplace_back(float(px), float(py), float(h + rng.normal(0, 0.3)));
      c.normals.push_back(n.cast<float>());
    }
  return c;
}

// Indices 0, step, 2 step, ... below n.
inline std::vector<int> every_nth(size_t n, size_t step) {
  std::vector<int> k;
  for (size_t i = 0; i < n; i += step) k.push_back(static_cast<int>(i));
  return k;
}

}  // namespace pb::localtest
