// Test helpers for the scene generator: exact point-to-mesh distance through
// a uniform grid of triangles, and percentiles.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>
#include <unordered_map>
#include <vector>

#include "core/types.h"

namespace pbtest {

using pb::Vec3;

// Closest point on triangle abc to p (Ericson, Real-Time Collision Detection, 5.1.5).
inline Vec3 closest_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

// Distance from points to a mesh surface, exact up to `cap` (farther points
// report cap).
class MeshDistance {
 public:
  MeshDistance(const pb::Mesh& mesh, double cap) : cap_(cap) {
    for (const auto& v : mesh.vertices) V_.push_back(v.cast<double>());
    F_ = mesh.faces;
    const double diam = mesh.bounds().diagonal().norm();
    cell_ = std::max(cap, diam / 64.0);
    for (size_t f = 0; f < F_.size(); ++f) {
      Eigen::AlignedBox3d b;
      for (int k = 0; k < 3; ++k) b.extend(V_[F_[f][k]]);
      const auto lo = cell(b.min()), hi = cell(b.max());
      for (int x = lo[0]; x <= hi[0]; ++x)
        for (int y = lo[1]; y <= hi[1]; ++y)
          for (int z = lo[2]; z <= hi[2]; ++z) grid_[key(x, y, z)].push_back(static_cast<int>(f));
    }
  }

  double distance(const Vec3& p) const {
    const auto c = cell(p);
    double best = cap_;
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const auto it = grid_.find(key(c[0] + dx, c[1] + dy, c[2] + dz));
          if (it == grid_.end()) continue;
          for (int f : it->second) {
            const Vec3 q = closest_on_triangle(p, V_[F_[f][0]], V_[F_[f][1]], V_[F_[f][2]]);
            best = std::min(best, (q - p).norm());
          }
        }
    return best;
  }

 private:
  std::array<int, 3> cell(const Vec3& p) const {
    return {static_cast<int>(std::floor(p.x() / cell_)), static_cast<int>(std::floor(p.y() / cell_)),
            static_cast<int>(std::floor(p.z() / cell_))};
  }
  static uint64_t key(int x, int y, int z) {
    return (static_cast<uint64_t>(x + (1 << 20)) << 42) | (static_cast<uint64_t>(y + (1 << 20)) << 21) |
           static_cast<uint64_t>(z + (1 << 20));
  }
  double cap_, cell_;
  std::vector<Vec3> V_;
  std::vector<Eigen::Vector3i> F_;
  std::unordered_map<uint64_t, std::vector<int>> grid_;
};

inline double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  const size_t k = std::min(v.size() - 1, static_cast<size_t>(q * (v.size() - 1) + 0.5));
  std::nth_element(v.begin(), v.begin() + k, v.end());
  return v[k];
}

// A fresh temporary folder (removed by the caller).
inline std::string temp_dir(const std::string& tag) {
  char buf[] = "/tmp/posebench_XXXXXX";
  const char* d = mkdtemp(buf);
  return std::string(d ? d : "/tmp") + (tag.empty() ? "" : "");
}

}  // namespace pbtest
