#include "recognition/preprocess/voxel_grid.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>

#include "recognition/cell_table.h"
#include "recognition/preprocess/voxel_keys.h"

namespace pb {

namespace {

using Key = CellKey;  // cell index, in sort priority order

// Points grouped by cell: cell_of[i] (or -1), cells numbered in order of
// first appearance, the first point of each cell and its count; `order`
// lists the cells in output (key) order. The points keep first-appearance
// cell ids (no renumbering pass over every point): only the output is
// written in key order.
struct Cells {
  std::vector<int> cell_of;
  std::vector<int> first, count;
  std::vector<int> order;
  size_t size() const { return first.size(); }
};

// CellTable for keys of at most 32 bits (the packed keys of image-sized
// grids): key and slot side by side in one 8-byte entry, so a probe touches
// one cache line (a table frame's 50,000 cells: 1 MB of entries instead of
// 1.5 MB in two arrays). An empty entry has slot -1 (the high half all
// ones).
class CellTable32 {
 public:
  explicit CellTable32(size_t expected) {
    size_t cap = 64;
    while (cap < 2 * expected) cap *= 2;
    entries_.assign(cap, kEmpty);
  }
  int find_or_insert(uint64_t key, int fresh, bool* inserted) {
    if (2 * (size_ + 1) > entries_.size()) grow();
    const uint32_t k = static_cast<uint32_t>(key);
    size_t i = static_cast<size_t>(cell_mix(key)) & (entries_.size() - 1);
    *inserted = false;
    for (;; i = (i + 1) & (entries_.size() - 1)) {
      const uint64_t e = entries_[i];
      if (e == kEmpty) break;
      if (static_cast<uint32_t>(e) == k) return static_cast<int>(e >> 32);
    }
    entries_[i] = static_cast<uint64_t>(static_cast<uint32_t>(fresh)) << 32 | k;
    ++size_;
    *inserted = true;
    return fresh;
  }

 private:
  static constexpr uint64_t kEmpty = ~uint64_t(0);  // slot -1: no cell has it
  void grow() {
    std::vector<uint64_t> old(2 * entries_.size(), kEmpty);
    old.swap(entries_);
    for (const uint64_t e : old) {
      if (e == kEmpty) continue;
      size_t i = static_cast<size_t>(cell_mix(static_cast<uint64_t>(static_cast<uint32_t>(e)))) & (entries_.size() - 1);
      while (entries_[i] != kEmpty) i = (i + 1) & (entries_.size() - 1);
      entries_[i] = e;
    }
  }
  std::vector<uint64_t> entries_;
  size_t size_ = 0;
};

// The cell keys of the points in first-appearance order, grouped: key_of(i)
// gives point i's key, `skip(i)` says it has none. A point's cell is looked
// for in the previous point's (neighbouring pixels mostly share a cell), and
// only then in the hash table. (A guess from the cell last seen in the
// point's pixel column, tried before the table, cost more than the lookups
// it saved: a simulated Astra table frame 5.3 -> 4.8 ms without it.)
template <class K, class Table = CellTable<K>, class KeyOf, class Skip>
Cells group_by(size_t n, KeyOf key_of, Skip skip, std::vector<K>& keys) {
  Cells c;
  c.cell_of.assign(n, -1);
  Table slot(n / 8 + 16);
  // At most one cell per point: written by index into scratch arrays left
  // uninitialized (a table frame's: 4 MB not cleared), copied out at the
  // end.
  const std::unique_ptr<K[]> key_buf(new K[n]);
  const std::unique_ptr<int[]> first_buf(new int[n]), count_buf(new int[n]);
  int cells = 0;
  K last{};
  int last_slot = -1;
  for (size_t i = 0; i < n; ++i) {
    if (skip(i)) continue;
    const K k = key_of(i);
    int s = last_slot;
    if (s < 0 || !(k == last)) {
      bool fresh = false;
      s = slot.find_or_insert(k, cells, &fresh);
      if (fresh) {
        key_buf[static_cast<size_t>(cells)] = k;
        first_buf[static_cast<size_t>(cells)] = static_cast<int>(i);
        count_buf[static_cast<size_t>(cells)] = 0;
        ++cells;
      }
      last = k;
      last_slot = s;
    }
    ++count_buf[static_cast<size_t>(s)];
    c.cell_of[i] = s;
  }
  keys.assign(key_buf.get(), key_buf.get() + cells);
  c.first.assign(first_buf.get(), first_buf.get() + cells);
  c.count.assign(count_buf.get(), count_buf.get() + cells);
  return c;
}

// Sorts the cells by their packed keys (unique, below 2^bits): for keys of
// at most 32 bits an LSD radix sort of key << 32 | cell on the key's bits,
// 11 at a time; longer keys are sorted as (key, cell) pairs.
void sorted_order(const std::vector<uint64_t>& keys, int bits, std::vector<int>& order) {
  const size_t m = keys.size();
  order.resize(m);
  if (bits > 32) {
    std::vector<std::pair<uint64_t, int>> keyed(m);
    for (size_t k = 0; k < m; ++k) keyed[k] = {keys[k], static_cast<int>(k)};
    std::sort(keyed.begin(), keyed.end());
    for (size_t k = 0; k < m; ++k) order[k] = keyed[k].second;
    return;
  }
  std::vector<uint64_t> a(m), b(m);
  for (size_t k = 0; k < m; ++k) a[k] = keys[k] << 32 | static_cast<uint64_t>(k);
  constexpr int kDigit = 11;
  for (int shift = 32; shift < 32 + bits; shift += kDigit) {
    size_t count[(1 << kDigit) + 1] = {};
    for (const uint64_t v : a) ++count[((v >> shift) & ((1u << kDigit) - 1)) + 1];
    for (int d = 0; d < (1 << kDigit); ++d) count[d + 1] += count[d];
    for (const uint64_t v : a) b[count[(v >> shift) & ((1u << kDigit) - 1)]++] = v;
    a.swap(b);
  }
  for (size_t k = 0; k < m; ++k) order[k] = static_cast<int>(a[k] & 0xffffffffu);
}

// Bits needed for the values 0..v.
inline int bit_width(uint64_t v) {
  int b = 0;
  while (b < 64 && (v >> b) != 0) ++b;
  return b;
}

// Groups the points by cell, with the key order of the cells (PCL's: z, then
// y, then x for kZYX). When every axis spans fewer than 2^21 cells (always,
// for images at sensor range and millimetre-scale leaves) the key is one
// integer (voxel_keys.h): hashing, comparing and sorting it is cheap.
// Otherwise the triple itself is the key.
Cells group(const std::vector<Vec3f>& pts, const VoxelGridOptions& opt) {
  const size_t n = pts.size();
  const double inv = 1.0 / opt.leaf_mm;
  const bool divide = opt.cell_index == VoxelGridOptions::CellIndex::kDivide;
  const bool zyx = opt.order == VoxelGridOptions::Order::kZYX;
  auto cell = [&](float v) { return detail::floor_to_int(divide ? v / opt.leaf_mm : v * inv); };
  const int ax[3] = {zyx ? 2 : 0, 1, zyx ? 0 : 2};  // priority order of the axes
  float mn[3], mx[3];  // the box of the finite points
  if (opt.box) {
    std::copy(opt.box, opt.box + 3, mn);
    std::copy(opt.box + 3, opt.box + 6, mx);
  }
  if (opt.box ? !(mn[0] <= mx[0]) : !detail::finite_box(pts.data(), n, mn, mx))
    return Cells{std::vector<int>(n, -1), {}, {}, {}};
  detail::PackedGrid g;
  g.leaf = opt.leaf_mm;
  g.divide = divide;
  g.int32_cells = true;
  int64_t span = 0;
  int width[3];
  for (int d = 0; d < 3; ++d) {
    g.axis[d] = ax[d];
    g.lo[d] = cell(mn[ax[d]]);  // the cell index is monotonic in the coordinate
    const int64_t hi = cell(mx[ax[d]]);
    span = std::max(span, hi - g.lo[d]);
    width[d] = bit_width(static_cast<uint64_t>(hi - g.lo[d]));
    g.int32_cells = g.int32_cells && g.lo[d] >= std::numeric_limits<int32_t>::min() &&
                    hi <= std::numeric_limits<int32_t>::max();
  }
  if (span < (int64_t(1) << 21)) {
    g.shift[0] = width[1] + width[2];
    g.shift[1] = width[2];
    const std::unique_ptr<uint64_t[]> point_key(new uint64_t[n]);  // every one written
    detail::packed_cell_keys(pts.data(), n, g, point_key.get());
    std::vector<uint64_t> keys;
    const int bits = width[0] + width[1] + width[2];
    const auto key_of = [&](size_t i) { return point_key[i]; };
    const auto skip = [&](size_t i) { return point_key[i] == detail::kNoCell; };
    Cells c = bits <= 32 ? group_by<uint64_t, CellTable32>(n, key_of, skip, keys)
                         : group_by<uint64_t>(n, key_of, skip, keys);
    sorted_order(keys, bits, c.order);
    return c;
  }
  std::vector<Key> keys;
  Cells c = group_by<Key>(
      n, [&](size_t i) { return Key{cell(pts[i][ax[0]]), cell(pts[i][ax[1]]), cell(pts[i][ax[2]])}; },
      [&](size_t i) { return !pts[i].allFinite(); }, keys);
  std::vector<std::pair<Key, int>> keyed(keys.size());
  for (size_t k = 0; k < keys.size(); ++k) keyed[k] = {keys[k], static_cast<int>(k)};
  std::sort(keyed.begin(), keyed.end());
  c.order.resize(keyed.size());
  for (size_t k = 0; k < keyed.size(); ++k) c.order[k] = keyed[k].second;
  return c;
}

// Centroids accumulated in input order (double).
std::vector<Vec3> centroids(const std::vector<Vec3f>& pts, const Cells& c) {
  std::vector<Vec3> sum(c.size(), Vec3::Zero());
  for (size_t i = 0; i < pts.size(); ++i)
    if (c.cell_of[i] >= 0) sum[static_cast<size_t>(c.cell_of[i])] += pts[i].cast<double>();
  for (size_t k = 0; k < c.size(); ++k) sum[k] /= static_cast<double>(c.count[k]);
  return sum;
}

// Splits each cell into clusters of similar normal (VoxelGridOptions::
// normal_cluster_deg): the returned Cells have one entry per cluster, in
// cell order and, within a cell, creation order.
Cells split_by_normal(const Cells& c, const std::vector<Vec3f>& normals, double max_deg) {
  const float min_cos = static_cast<float>(std::cos(max_deg * M_PI / 180.0));
  std::vector<std::vector<int>> clusters_of(c.size());  // cell -> its clusters
  Cells out;
  out.cell_of.assign(c.cell_of.size(), -1);
  for (size_t i = 0; i < c.cell_of.size(); ++i) {
    const int k = c.cell_of[i];
    if (k < 0) continue;
    int home = -1;
    for (int cl : clusters_of[static_cast<size_t>(k)])
      if (normals[static_cast<size_t>(out.first[static_cast<size_t>(cl)])].dot(normals[i]) >= min_cos) {
        home = cl;
        break;
      }
    if (home < 0) {
      home = static_cast<int>(out.first.size());
      clusters_of[static_cast<size_t>(k)].push_back(home);
      out.first.push_back(static_cast<int>(i));
      out.count.push_back(0);
    }
    out.cell_of[i] = home;
    ++out.count[static_cast<size_t>(home)];
  }
  for (int k : c.order)
    for (int cl : clusters_of[static_cast<size_t>(k)]) out.order.push_back(cl);
  return out;
}

}  // namespace

PointSet voxel_downsample(const PointSet& in, const VoxelGridOptions& opt) {
  if (!(opt.leaf_mm > 0) || in.points.empty()) return in;
  const size_t n = in.points.size();
  const bool has_n = in.normals.size() == n, has_c = in.curvature.size() == n, has_px = in.pixel.size() == n;
  const Cells c = has_n && opt.normal_cluster_deg > 0
                      ? split_by_normal(group(in.points, opt), in.normals, opt.normal_cluster_deg)
                      : group(in.points, opt);
  const std::vector<Vec3> centroid = centroids(in.points, c);
  // Each field in its own pass over the points (input order, as the sums'
  // order must be).
  std::vector<Vec3> nsum(has_n ? c.size() : 0, Vec3::Zero());
  std::vector<double> csum(has_c ? c.size() : 0, 0.0);
  std::vector<int> best_px(has_px ? c.size() : 0, -1);
  if (has_n)
    for (size_t i = 0; i < n; ++i)
      if (const int k = c.cell_of[i]; k >= 0) nsum[static_cast<size_t>(k)] += in.normals[i].cast<double>();
  if (has_c)
    for (size_t i = 0; i < n; ++i)
      if (const int k = c.cell_of[i]; k >= 0) csum[static_cast<size_t>(k)] += in.curvature[i];
  if (has_px) {  // the point nearest the centroid; ties: the smaller pixel
    std::vector<double> best_d(c.size(), std::numeric_limits<double>::infinity());
    for (size_t i = 0; i < n; ++i) {
      const int k = c.cell_of[i];
      if (k < 0) continue;
      const double d = (in.points[i].cast<double>() - centroid[static_cast<size_t>(k)]).squaredNorm();
      const int px = in.pixel[i];
      double& bd = best_d[static_cast<size_t>(k)];
      int& bp = best_px[static_cast<size_t>(k)];
      // Without branches: which point wins is data, not a pattern to predict.
      const bool better = (d < bd) | ((d == bd) & (px < bp));
      bd = better ? d : bd;
      bp = better ? px : bp;
    }
  }
  PointSet out;
  out.source_width = in.source_width;
  out.source_height = in.source_height;
  out.points.reserve(c.size());
  for (const int cell : c.order) {
    const size_t k = static_cast<size_t>(cell);
    if (has_n) {
      const double l = nsum[k].norm();
      if (opt.drop_cancelled_normals > 0 && !(l > opt.drop_cancelled_normals * c.count[k])) continue;
      out.normals.push_back(l > 0 ? Vec3f((nsum[k] / l).cast<float>()) : in.normals[static_cast<size_t>(c.first[k])]);
    }
    out.points.push_back(centroid[k].cast<float>());
    if (has_c) out.curvature.push_back(static_cast<float>(csum[k] / c.count[k]));
    if (has_px) out.pixel.push_back(best_px[k]);
  }
  return out;
}

std::vector<int> voxel_nearest_points(const PointSet& in, const VoxelGridOptions& opt) {
  std::vector<int> out;
  if (in.empty() || !(opt.leaf_mm > 0)) return out;
  const Cells c = group(in.points, opt);
  const std::vector<Vec3> centroid = centroids(in.points, c);
  out.assign(c.size(), -1);
  std::vector<double> best(c.size(), std::numeric_limits<double>::max());
  for (size_t i = 0; i < in.points.size(); ++i) {  // input order: ties -> lowest index
    const int k = c.cell_of[i];
    if (k < 0) continue;
    const double d = (in.points[i].cast<double>() - centroid[static_cast<size_t>(k)]).squaredNorm();
    if (d < best[static_cast<size_t>(k)]) {
      best[static_cast<size_t>(k)] = d;
      out[static_cast<size_t>(k)] = static_cast<int>(i);
    }
  }
  std::vector<int> sorted(c.size());
  for (size_t r = 0; r < c.order.size(); ++r) sorted[r] = out[static_cast<size_t>(c.order[r])];
  return sorted;
}

PointSet voxel_downsample_to(const PointSet& in, int target, const VoxelGridOptions& base) {
  VoxelGridOptions o = base;
  auto grid = [&](double leaf) {
    o.leaf_mm = leaf;
    return voxel_downsample(in, o);
  };
  if (in.points.size() <= static_cast<size_t>(target)) return grid(1e-3);
  Eigen::AlignedBox3f box;
  for (const auto& p : in.points) box.extend(p);
  double lo = 1e-3, hi = std::max(1e-2, static_cast<double>(box.diagonal().norm()));
  PointSet best = grid(hi);
  for (int it = 0; it < 30; ++it) {
    const double mid = 0.5 * (lo + hi);
    PointSet c = grid(mid);
    if (c.points.size() <= static_cast<size_t>(target)) {
      hi = mid;
      best = std::move(c);
    } else {
      lo = mid;
    }
  }
  return best;
}

}  // namespace pb
