#include "recognition/grid_nearest.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace pb {

namespace {

constexpr double kMaxCells = 4.0 * 1024 * 1024;
// More points per occupied cell than this on average: no grid.
constexpr double kMaxPerCell = 8;
// Queries whose box spans more cells than this on an axis go to the kd-tree.
constexpr int kMaxSpan = 3;
// The kd-tree's leaf size (its answers do not depend on it; ICP's tree had
// 24, about 8% faster than 8 on the warehouse).
constexpr int kTreeLeafSize = 24;

// floor(x) for finite x (no libm call: baseline x86-64 has no rounding
// instruction).
inline double floor_of(double x) {
  const double t = static_cast<double>(static_cast<int64_t>(x));
  return t > x ? t - 1 : t;
}

// The squared distance as KdTree3 computes it (its leaves and its hint):
// x^2 + (y^2 + z^2) of the point minus q, in float.
inline float sq_dist(float px, float py, float pz, const Vec3f& q) {
  const float dx = px - q.x(), dy = py - q.y(), dz = pz - q.z();
  return dx * dx + (dy * dy + dz * dz);
}

}  // namespace

GridNearest::GridNearest(const std::vector<Vec3f>& points, double cell) : tree_(points, kTreeLeafSize) {
  const size_t n = points.size();
  index_of_.assign(n, -1);
  double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
  bool any = false;
  for (const Vec3f& p : points) {
    if (!p.allFinite()) continue;
    for (int a = 0; a < 3; ++a) {
      lo[a] = any ? std::min(lo[a], static_cast<double>(p[a])) : p[a];
      hi[a] = any ? std::max(hi[a], static_cast<double>(p[a])) : p[a];
    }
    any = true;
  }
  if (!any) return;
  double side = cell > 0 && std::isfinite(cell) ? cell : 1.0;
  const auto cells_of = [&](double sd) {
    double cells = 1;
    for (int a = 0; a < 3; ++a) cells *= std::floor((hi[a] - lo[a]) / sd) + 1;
    return cells;
  };
  while (cells_of(side) > kMaxCells) side *= 2;
  // Cells of many points (a surface sampled densely for the bound's size)
  // make every query scan them: then the kd-tree answers every query.
  {
    const double inv = 1.0 / side;
    int d[3];
    for (int a = 0; a < 3; ++a) d[a] = static_cast<int>(floor_of((hi[a] - lo[a]) * inv)) + 1;
    std::vector<uint8_t> used(static_cast<size_t>(d[0]) * static_cast<size_t>(d[1]) * static_cast<size_t>(d[2]), 0);
    size_t occupied = 0, m = 0;
    for (const Vec3f& p : points) {
      if (!p.allFinite()) continue;
      size_t c = 0;
      for (int a = 2; a >= 0; --a)
        c = c * static_cast<size_t>(d[a]) +
            static_cast<size_t>(std::clamp(static_cast<int>(floor_of((p[a] - lo[a]) * inv)), 0, d[a] - 1));
      occupied += used[c] == 0;
      used[c] = 1;
      ++m;
    }
    if (static_cast<double>(m) > kMaxPerCell * static_cast<double>(occupied)) return;
  }
  inv_ = 1.0 / side;
  scale_ = 1;
  for (int a = 0; a < 3; ++a) {
    origin_[a] = lo[a];
    dims_[a] = static_cast<int>(std::floor((hi[a] - lo[a]) * inv_)) + 1;
    scale_ = std::max(scale_, 1 + std::max(std::abs(lo[a]), std::abs(hi[a])));
  }
  // Counting sort of the points by cell (input order within a cell).
  const size_t ncells = static_cast<size_t>(dims_[0]) * static_cast<size_t>(dims_[1]) * static_cast<size_t>(dims_[2]);
  std::vector<uint32_t> cell_of(n, 0);
  start_.assign(ncells + 1, 0);
  for (size_t i = 0; i < n; ++i) {
    const Vec3f& p = points[i];
    if (!p.allFinite()) continue;
    size_t c = 0;
    for (int a = 2; a >= 0; --a) {
      const int k = std::min(dims_[a] - 1, static_cast<int>(floor_of((p[a] - origin_[a]) * inv_)));
      c = c * static_cast<size_t>(dims_[a]) + static_cast<size_t>(std::max(0, k));
    }
    cell_of[i] = static_cast<uint32_t>(c);
    ++start_[c + 1];
  }
  for (size_t c = 0; c < ncells; ++c) start_[c + 1] += start_[c];
  const size_t m = start_[ncells];
  x_.resize(m);
  y_.resize(m);
  z_.resize(m);
  index_.resize(m);
  std::vector<uint32_t> fill(start_.begin(), start_.end() - 1);
  for (size_t i = 0; i < n; ++i) {
    const Vec3f& p = points[i];
    if (!p.allFinite()) continue;
    const uint32_t s = fill[cell_of[i]]++;
    x_[s] = p.x();
    y_[s] = p.y();
    z_[s] = p.z();
    index_[s] = static_cast<int>(i);
    index_of_[i] = static_cast<int>(s);
  }
  grid_ = true;
}

int GridNearest::nearest(const Vec3f& q, float* sq_dist_out, float max_sq_dist, int hint) const {
  if (!grid_) return tree_.nearest(q, sq_dist_out, max_sq_dist, hint);
  int best = -1;
  float best_d = max_sq_dist;
  if (hint >= 0 && static_cast<size_t>(hint) < index_of_.size() && index_of_[static_cast<size_t>(hint)] >= 0) {
    const size_t s = static_cast<size_t>(index_of_[static_cast<size_t>(hint)]);
    const float d = sq_dist(x_[s], y_[s], z_[s], q);
    if (d < best_d) {
      best_d = d;
      best = hint;
    }
  }
  if (q.allFinite() && best_d >= 0) {
    // Every point of squared distance at most best_d lies within r of q on
    // each axis: r covers the float rounding of the distances (relative 1e-5
    // against about 2e-7), the double rounding of the cell bounds and
    // squares that underflow (absolute, 1e-9 of the coordinates' scale).
    const double r = std::sqrt(static_cast<double>(best_d)) * (1 + 1e-5) + 1e-9 * (scale_ + std::abs(q.x()) +
                                                                                   std::abs(q.y()) + std::abs(q.z()));
    // The cells [lo, hi] per axis: the box's ends in cell units, clamped to
    // the grid (truncation is the floor there: the values are >= 0).
    int lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
      const double l = (q[a] - r - origin_[a]) * inv_, h = (q[a] + r - origin_[a]) * inv_;
      if (!(h >= 0) || !(l < dims_[a])) {  // the ball misses the grid
        if (sq_dist_out) *sq_dist_out = best >= 0 ? best_d : std::numeric_limits<float>::infinity();
        return best;
      }
      lo[a] = l > 0 ? static_cast<int>(l) : 0;
      hi[a] = h < dims_[a] - 1 ? static_cast<int>(h) : dims_[a] - 1;
      if (hi[a] - lo[a] >= kMaxSpan) return tree_.nearest(q, sq_dist_out, max_sq_dist, hint);
    }
    for (int cz = lo[2]; cz <= hi[2]; ++cz)
      for (int cy = lo[1]; cy <= hi[1]; ++cy) {
        const size_t row = (static_cast<size_t>(cz) * static_cast<size_t>(dims_[1]) + static_cast<size_t>(cy)) *
                           static_cast<size_t>(dims_[0]);
        // The cells lo[0]..hi[0] of a row are consecutive slots.
        const uint32_t b = start_[row + static_cast<size_t>(lo[0])], e = start_[row + static_cast<size_t>(hi[0]) + 1];
        for (uint32_t s = b; s < e; ++s) {
          const float d = sq_dist(x_[s], y_[s], z_[s], q);
          if (d < best_d || (d == best_d && best >= 0 && index_[s] < best)) {
            best_d = d;
            best = index_[s];
          }
        }
      }
  }
  if (sq_dist_out) *sq_dist_out = best >= 0 ? best_d : std::numeric_limits<float>::infinity();
  return best;
}

}  // namespace pb
