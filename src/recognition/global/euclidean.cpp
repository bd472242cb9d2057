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

#include "recognition/cell_table.h"
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
  // The cells numbered as they first come (which number a cell gets does
  // not change the clusters: components, then sorted).
  CellTable<CellKey> cell_id(points.size() / 2);
  std::vector<int> cell_of(points.size(), -1);  // then the points cell by cell (CSR)
  std::vector<CellKey> cells;
  for (size_t i = 0; i < points.size(); ++i) {
    const Vec3f& p = points[i];
    if (!p.allFinite()) continue;  // in no cluster (the pipeline's clouds are finite)
    CellKey c;
    for (int a = 0; a < 3; ++a) {
      const double v = std::floor(p[a] / edge);
      if (!(std::abs(v) < 1e9))
        throw std::invalid_argument("euclidean_clusters: a tolerance of " + std::to_string(tolerance_mm) +
                                    " mm is too small for points " + std::to_string(p[a]) + " mm away");
      c[static_cast<size_t>(a)] = static_cast<int64_t>(v);
    }
    bool added = false;
    cell_of[i] = cell_id.find_or_insert(c, static_cast<int>(cells.size()), &added);
    if (added) cells.push_back(c);
  }
  // Each cell's points, in input order: start[a] .. start[a + 1] of `order`.
  std::vector<int> start(cells.size() + 1, 0), order;
  for (int k : cell_of)
    if (k >= 0) ++start[static_cast<size_t>(k) + 1];
  for (size_t a = 0; a < cells.size(); ++a) start[a + 1] += start[a];
  order.resize(static_cast<size_t>(start.back()));
  {
    std::vector<int> next(start.begin(), start.end() - 1);
    for (size_t i = 0; i < points.size(); ++i)
      if (const int k = cell_of[i]; k >= 0)
        order[static_cast<size_t>(next[static_cast<size_t>(k)]++)] = static_cast<int>(i);
  }
  const auto members = [&](size_t a) {
    return std::make_pair(order.data() + start[a], order.data() + start[a + 1]);
  };
  // The neighbour lookups: an array over the cells' box, padded by the two
  // cells a neighbour may lie beyond it, where that box is small (a table
  // scene's: tens of thousands of cells), so a neighbour is an offset
  // away; else the table.
  constexpr int64_t kDenseCells = int64_t(1) << 20;
  CellKey clo = cells.empty() ? CellKey{} : cells[0], chi = clo;
  for (const CellKey& c : cells)
    for (size_t a = 0; a < 3; ++a) clo[a] = std::min(clo[a], c[a]), chi[a] = std::max(chi[a], c[a]);
  const int64_t ex = chi[0] - clo[0] + 5, ey = chi[1] - clo[1] + 5, ez = chi[2] - clo[2] + 5;
  const bool dense = ex * ey <= kDenseCells && ex * ey * ez <= kDenseCells;
  std::vector<int> grid;
  const auto at = [&](const CellKey& c) {
    return ((c[2] - clo[2] + 2) * ey + (c[1] - clo[1] + 2)) * ex + (c[0] - clo[0] + 2);
  };
  if (dense) {
    grid.assign(static_cast<size_t>(ex * ey * ez), -1);
    for (size_t a = 0; a < cells.size(); ++a) grid[static_cast<size_t>(at(cells[a]))] = static_cast<int>(a);
  }
  Components comp(cells.size());
  for (size_t a = 0; a < cells.size(); ++a) {
    const CellKey& c = cells[a];
    const int64_t here = dense ? at(c) : 0;
    for (int dx = -2; dx <= 2; ++dx)
      for (int dy = -2; dy <= 2; ++dy)
        for (int dz = -2; dz <= 2; ++dz) {
          // Each pair of cells once: the offset must be lexicographically positive.
          if (dx < 0 || (dx == 0 && (dy < 0 || (dy == 0 && dz <= 0)))) continue;
          const int b = dense ? grid[static_cast<size_t>(here + (int64_t(dz) * ey + dy) * ex + dx)]
                              : cell_id.find(CellKey{c[0] + dx, c[1] + dy, c[2] + dz});
          if (b < 0) continue;
          if (comp.find(static_cast<int>(a)) == comp.find(b)) continue;
          bool near = false;
          const auto [ai, ae] = members(a);
          const auto [bi, be] = members(static_cast<size_t>(b));
          for (const int* i = ai; i != ae && !near; ++i)
            for (const int* j = bi; j != be; ++j)
              if (sq_dist(points[static_cast<size_t>(*i)], points[static_cast<size_t>(*j)]) < t2) {
                near = true;
                break;
              }
          if (near) comp.join(static_cast<int>(a), b);
        }
  }
  std::unordered_map<int, size_t> cluster_of;  // component root -> out index
  for (size_t a = 0; a < cells.size(); ++a) {
    const auto [it, added] = cluster_of.emplace(comp.find(static_cast<int>(a)), out.size());
    if (added) out.emplace_back();
    std::vector<int>& cl = out[it->second];
    const auto [ai, ae] = members(a);
    cl.insert(cl.end(), ai, ae);
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
