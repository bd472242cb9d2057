// Euclidean clusters, PCL-free: the connected components of the graph that
// joins two points closer than the tolerance (squared distance below t^2 in
// float, as FLANN's strict radius search that pcl::EuclideanClusterExtraction
// runs from every point), clusters outside [min, max] points dropped whole,
// as PCL drops them. Components do not depend on the order of a search, so
// the clusters are PCL's (clusters.cpp keeps PCL's as the reference,
// `GlobalClusters.SameAsPcl`).
//
// Instead of a radius search per point (hundreds of neighbours each when the
// tolerance is many voxels wide), the points go into a grid of cells of edge
// t / sqrt(3) (slightly less): two points of one cell are always closer than
// t, so a cell is connected inside; two cells up to two steps apart on each
// axis are joined as soon as one pair of their points is closer than t, and
// not searched once they are in one component.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include "recognition/global/internal.h"

namespace pb::global {

namespace {

struct Components {
  std::vector<int> parent;
  explicit Components(size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  int find(int a) {
    while (parent[static_cast<size_t>(a)] != a) {
      parent[static_cast<size_t>(a)] = parent[static_cast<size_t>(parent[static_cast<size_t>(a)])];
      a = parent[static_cast<size_t>(a)];
    }
    return a;
  }
  void join(int a, int b) {
    a = find(a), b = find(b);
    if (a != b) parent[static_cast<size_t>(std::max(a, b))] = std::min(a, b);
  }
};

// FLANN's squared distance (L2_Simple: the three squared differences summed
// in float, in order).
inline float sq_dist(const Vec3f& a, const Vec3f& b) {
  const float dx = a.x() - b.x(), dy = a.y() - b.y(), dz = a.z() - b.z();
  return dx * dx + dy * dy + dz * dz;
}

struct Cell {
  int x, y, z;
  bool operator==(const Cell& o) const { return x == o.x && y == o.y && z == o.z; }
};
struct CellHash {
  size_t operator()(const Cell& c) const {
    return static_cast<size_t>((static_cast<uint64_t>(static_cast<uint32_t>(c.x)) * 73856093u) ^
                               (static_cast<uint64_t>(static_cast<uint32_t>(c.y)) * 19349663u) ^
                               (static_cast<uint64_t>(static_cast<uint32_t>(c.z)) * 83492791u));
  }
};

}  // namespace

std::vector<std::vector<int>> euclidean_clusters(const std::vector<Vec3f>& points, double tolerance_mm,
                                                 int min_points, int max_points) {
  std::vector<std::vector<int>> out;
  if (points.empty() || static_cast<int>(points.size()) < std::max(min_points, 1) || !(tolerance_mm > 0)) return out;
  // PCL's bound: the tolerance as a float, squared in double, then a float.
  const double tol_f = static_cast<float>(tolerance_mm);
  const float t2 = static_cast<float>(tol_f * tol_f);
  // Cells small enough that their diagonal stays below t after rounding.
  const double edge = tolerance_mm / std::sqrt(3.0) * (1.0 - 1e-4);
  std::unordered_map<Cell, int, CellHash> cell_id;
  std::vector<std::vector<int>> members;
  std::vector<Cell> cells;
  for (size_t i = 0; i < points.size(); ++i) {
    const Vec3f& p = points[i];
    if (!p.allFinite()) continue;  // in no cluster (the pipeline's clouds are finite)
    int c[3];
    for (int a = 0; a < 3; ++a) {
      const double v = std::floor(p[a] / edge);
      if (!(std::abs(v) < 1e9))
        throw std::invalid_argument("euclidean_clusters: a tolerance of " + std::to_string(tolerance_mm) +
                                    " mm is too small for points " + std::to_string(p[a]) + " mm away");
      c[a] = static_cast<int>(v);
    }
    const auto [it, added] = cell_id.emplace(Cell{c[0], c[1], c[2]}, static_cast<int>(members.size()));
    if (added) {
      members.emplace_back();
      cells.push_back(Cell{c[0], c[1], c[2]});
    }
    members[static_cast<size_t>(it->second)].push_back(static_cast<int>(i));
  }
  Components comp(members.size());
  for (size_t a = 0; a < members.size(); ++a) {
    const Cell& c = cells[a];
    for (int dx = -2; dx <= 2; ++dx)
      for (int dy = -2; dy <= 2; ++dy)
        for (int dz = -2; dz <= 2; ++dz) {
          // Each pair of cells once: the offset must be lexicographically positive.
          if (dx < 0 || (dx == 0 && (dy < 0 || (dy == 0 && dz <= 0)))) continue;
          const auto it = cell_id.find(Cell{c.x + dx, c.y + dy, c.z + dz});
          if (it == cell_id.end()) continue;
          const int b = it->second;
          if (comp.find(static_cast<int>(a)) == comp.find(b)) continue;
          bool near = false;
          for (int i : members[a]) {
            for (int j : members[static_cast<size_t>(b)])
              if (sq_dist(points[static_cast<size_t>(i)], points[static_cast<size_t>(j)]) < t2) {
                near = true;
                break;
              }
            if (near) break;
          }
          if (near) comp.join(static_cast<int>(a), b);
        }
  }
  std::unordered_map<int, size_t> cluster_of;  // component root -> out index
  for (size_t a = 0; a < members.size(); ++a) {
    const auto [it, added] = cluster_of.emplace(comp.find(static_cast<int>(a)), out.size());
    if (added) out.emplace_back();
    std::vector<int>& cl = out[it->second];
    cl.insert(cl.end(), members[a].begin(), members[a].end());
  }
  const size_t lo = static_cast<size_t>(std::max(min_points, 1)), hi = static_cast<size_t>(std::max(max_points, 1));
  out.erase(std::remove_if(out.begin(), out.end(), [&](const auto& c) { return c.size() < lo || c.size() > hi; }),
            out.end());
  for (auto& c : out) std::sort(c.begin(), c.end());
  // Largest first; ties by the first index, so the order never depends on
  // the sort implementation.
  std::stable_sort(out.begin(), out.end(), [](const auto& a, const auto& b) {
    if (a.size() != b.size()) return a.size() > b.size();
    return a.front() < b.front();
  });
  return out;
}

}  // namespace pb::global
