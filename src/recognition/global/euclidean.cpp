// Euclidean clusters, PCL-free: the connected components of the graph that
// joins two points closer than the tolerance (squared distance below t^2 in
// float, as FLANN's strict radius search that pcl::EuclideanClusterExtraction
// runs from every point), clusters outside [min, max] points dropped whole,
// as PCL drops them. Components do not depend on the order of a search, so
// the clusters are PCL's (tests/pcl_reference/clusters_pcl.cpp keeps PCL's as the reference,
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

// The points in cells of edge `edge`: the cells' keys as they first come
// (which number a cell gets does not change the clusters: components, then
// sorted), and each cell's points in input order, start[a] .. start[a + 1]
// of `order` (CSR). A non-finite point is in no cell.
struct Cells {
  CellTable<CellKey> id;
  std::vector<CellKey> keys;
  std::vector<int> start, order;
  explicit Cells(size_t n) : id(n / 2) {}
  std::pair<const int*, const int*> members(size_t a) const {
    return {order.data() + start[a], order.data() + start[a + 1]};
  }
};

Cells cells_of(const std::vector<Vec3f>& points, double edge, double tolerance_mm) {
  Cells cells(points.size());
  std::vector<int> cell_of(points.size(), -1);
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
    cell_of[i] = cells.id.find_or_insert(c, static_cast<int>(cells.keys.size()), &added);
    if (added) cells.keys.push_back(c);
  }
  cells.start.assign(cells.keys.size() + 1, 0);
  for (int k : cell_of)
    if (k >= 0) ++cells.start[static_cast<size_t>(k) + 1];
  for (size_t a = 0; a < cells.keys.size(); ++a) cells.start[a + 1] += cells.start[a];
  cells.order.resize(static_cast<size_t>(cells.start.back()));
  std::vector<int> next(cells.start.begin(), cells.start.end() - 1);
  for (size_t i = 0; i < points.size(); ++i)
    if (const int k = cell_of[i]; k >= 0)
      cells.order[static_cast<size_t>(next[static_cast<size_t>(k)]++)] = static_cast<int>(i);
  return cells;
}

// A cell's neighbours: the cells up to two steps away on each axis, each
// pair once (the offset from a to b lexicographically positive). Where the
// cells' box, padded by the two cells a neighbour may lie beyond it, is
// small (at most 2^20 cells), an array over it, so a neighbour is an
// offset away. Else, where the box has at most 2^18 x-y columns (or 16
// per cell), the cells by column, each column's sorted by z: a neighbour
// lies in one of 13 columns within two steps in z. Else the hashed table.
// The same pairs of cells whichever it is, so the same components. (On 24
// table_astra frames with CVFH's settings, the scene's box held 0.1-7.4
// million cells in 1,700-37,000 columns: its far points make it large.)
class Neighbours {
 public:
  explicit Neighbours(const Cells& cells) : cells_(cells) {
    const std::vector<CellKey>& keys = cells.keys;
    lo_ = keys.empty() ? CellKey{} : keys[0];
    CellKey hi = lo_;
    for (const CellKey& c : keys)
      for (size_t a = 0; a < 3; ++a) lo_[a] = std::min(lo_[a], c[a]), hi[a] = std::max(hi[a], c[a]);
    ex_ = hi[0] - lo_[0] + 5, ey_ = hi[1] - lo_[1] + 5;
    const int64_t ez = hi[2] - lo_[2] + 5;
    if (ex_ * ey_ <= kDenseCells && ex_ * ey_ * ez <= kDenseCells) {
      kind_ = Kind::kDense;
      grid_.assign(static_cast<size_t>(ex_ * ey_ * ez), -1);
      for (size_t a = 0; a < keys.size(); ++a) grid_[static_cast<size_t>(at(keys[a]))] = static_cast<int>(a);
    } else if (ex_ * ey_ <= std::max(kColumns, 16 * static_cast<int64_t>(keys.size()))) {
      kind_ = Kind::kColumns;
      grid_.assign(static_cast<size_t>(ex_ * ey_ + 1), 0);  // each column's start in column_cells_
      for (const CellKey& c : keys) ++grid_[static_cast<size_t>(column(c)) + 1];
      for (size_t k = 1; k < grid_.size(); ++k) grid_[k] += grid_[k - 1];
      column_cells_.resize(keys.size());
      std::vector<int> next(grid_.begin(), grid_.end() - 1);
      for (size_t a = 0; a < keys.size(); ++a)
        column_cells_[static_cast<size_t>(next[static_cast<size_t>(column(keys[a]))]++)] = static_cast<int>(a);
      for (size_t k = 0; k + 1 < grid_.size(); ++k)
        std::sort(column_cells_.begin() + grid_[k], column_cells_.begin() + grid_[k + 1],
                  [&](int a, int b) { return z(a) < z(b); });
    }
  }

  // f(b) for every neighbour b of cell a.
  template <class F>
  void forward(size_t a, F f) const {
    const CellKey& c = cells_.keys[a];
    if (kind_ == Kind::kColumns) {
      for (int dx = 0; dx <= 2; ++dx)
        for (int dy = dx == 0 ? 0 : -2; dy <= 2; ++dy) {
          const size_t k = static_cast<size_t>(column(c) + int64_t(dy) * ex_ + dx);
          // In a's own column only above it; a column may hold many cells
          // (a table top's spans its depth): from the first at z_lo on.
          const int64_t z_lo = dx == 0 && dy == 0 ? c[2] + 1 : c[2] - 2;
          const int* b = std::lower_bound(column_cells_.data() + grid_[k], column_cells_.data() + grid_[k + 1], z_lo,
                                          [&](int m, int64_t v) { return z(m) < v; });
          for (const int* e = column_cells_.data() + grid_[k + 1]; b != e && z(*b) <= c[2] + 2; ++b) f(*b);
        }
      return;
    }
    const int64_t here = kind_ == Kind::kDense ? at(c) : 0;
    for (int dx = 0; dx <= 2; ++dx)
      for (int dy = -2; dy <= 2; ++dy)
        for (int dz = -2; dz <= 2; ++dz) {
          if (dx == 0 && (dy < 0 || (dy == 0 && dz <= 0))) continue;
          const int b = kind_ == Kind::kDense ? grid_[static_cast<size_t>(here + (int64_t(dz) * ey_ + dy) * ex_ + dx)]
                                              : cells_.id.find(CellKey{c[0] + dx, c[1] + dy, c[2] + dz});
          if (b >= 0) f(b);
        }
  }

 private:
  // The array's and the columns' limits: their set-up (an array of that
  // many ints, cleared) stays small next to the lookups it saves.
  static constexpr int64_t kDenseCells = int64_t(1) << 20, kColumns = int64_t(1) << 18;
  enum class Kind { kDense, kColumns, kHashed };
  int64_t at(const CellKey& c) const {
    return ((c[2] - lo_[2] + 2) * ey_ + (c[1] - lo_[1] + 2)) * ex_ + (c[0] - lo_[0] + 2);
  }
  int64_t column(const CellKey& c) const { return (c[1] - lo_[1] + 2) * ex_ + (c[0] - lo_[0] + 2); }
  int64_t z(int a) const { return cells_.keys[static_cast<size_t>(a)][2]; }

  const Cells& cells_;
  Kind kind_ = Kind::kHashed;
  CellKey lo_;
  int64_t ex_ = 0, ey_ = 0;
  std::vector<int> grid_;          // kDense: the cell at each box position (-1: none); kColumns: column starts
  std::vector<int> column_cells_;  // kColumns: the cells column by column, by z within one
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
  const Cells cells = cells_of(points, tolerance_mm / std::sqrt(3.0) * (1.0 - 1e-4), tolerance_mm);
  const Neighbours neighbours(cells);
  Components comp(cells.keys.size());
  for (size_t a = 0; a < cells.keys.size(); ++a)
    neighbours.forward(a, [&](int b) {
      // Joined when not yet one component and one pair of their points is
      // closer than the tolerance.
      if (comp.find(static_cast<int>(a)) == comp.find(b)) return;
      const auto [ai, ae] = cells.members(a);
      const auto [bi, be] = cells.members(static_cast<size_t>(b));
      for (const int* i = ai; i != ae; ++i)
        for (const int* j = bi; j != be; ++j)
          if (sq_dist(points[static_cast<size_t>(*i)], points[static_cast<size_t>(*j)]) < t2) {
            comp.join(static_cast<int>(a), b);
            return;
          }
    });
  std::unordered_map<int, size_t> cluster_of;  // component root -> out index
  for (size_t a = 0; a < cells.keys.size(); ++a) {
    const auto [it, added] = cluster_of.emplace(comp.find(static_cast<int>(a)), out.size());
    if (added) out.emplace_back();
    std::vector<int>& cl = out[it->second];
    const auto [ai, ae] = cells.members(a);
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
