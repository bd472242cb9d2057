// KdTree3 (kdtree.h): the build, the leaf kernel, the nearest, radius and
// thinned searches, the search over the points not yet taken (Remaining)
// and the tree cut down to a subset of its points (restricted).
#include "recognition/kdtree.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#ifdef __SSE2__
#include <xmmintrin.h>
#endif

namespace pb {

// The leaf kernel and the radius traversal, used by the searches below.
inline int KdTree3::leaf_distances(const Vec3f& q, int i, int m, float bound, float* d4) const {
#ifdef __SSE2__
  // Four lanes read whole (the arrays are padded); lanes from m on are masked.
  const __m128 dx = _mm_sub_ps(_mm_loadu_ps(&xyz_[0][static_cast<size_t>(i)]), _mm_set1_ps(q.x()));
  const __m128 dy = _mm_sub_ps(_mm_loadu_ps(&xyz_[1][static_cast<size_t>(i)]), _mm_set1_ps(q.y()));
  const __m128 dz = _mm_sub_ps(_mm_loadu_ps(&xyz_[2][static_cast<size_t>(i)]), _mm_set1_ps(q.z()));
  const __m128 d = _mm_add_ps(_mm_mul_ps(dx, dx), _mm_add_ps(_mm_mul_ps(dy, dy), _mm_mul_ps(dz, dz)));
  _mm_storeu_ps(d4, d);
  return _mm_movemask_ps(_mm_cmple_ps(d, _mm_set1_ps(bound))) & ((1 << m) - 1);
#else
  int mask = 0;
  for (int k = 0; k < m; ++k) {
    d4[k] = (points_[static_cast<size_t>(i + k)] - q).squaredNorm();
    if (d4[k] <= bound) mask |= 1 << k;
  }
  return mask;
#endif
}

template <class F>
bool KdTree3::scan_leaf(const Node& n, const Vec3f& q, const float& bound, F&& f) const {
  float d4[4];
  for (int i = n.begin; i < n.end; i += 4) {
    const int m = std::min(4, n.end - i);
    for (int mask = leaf_distances(q, i, m, bound, d4); mask != 0; mask &= mask - 1) {
      const int k = __builtin_ctz(static_cast<unsigned>(mask));
      if (f(d4[k], i + k)) return true;
    }
  }
  return false;
}

// visit_radius (kdtree.h): near child first, the far one when the splitting
// plane is within the radius.
template <class F, class Skip>
void KdTree3::visit_radius(int node, const Vec3f& q, float r2, F& f, const Skip& skip) const {
  if (skip(node)) return;
  const Node& n = nodes_[static_cast<size_t>(node)];
  if (n.dim < 0) {  // the same distances as squaredNorm, visited in tree order
    scan_leaf(n, q, r2, [&](float d, int pos) {
      f(d, order_[static_cast<size_t>(pos)]);
      return false;
    });
    return;
  }
  const float diff = q[n.dim] - n.split;
  const int near = diff < 0 ? n.left : n.right, far = diff < 0 ? n.right : n.left;
  visit_radius(near, q, r2, f, skip);
  if (diff * diff <= r2) visit_radius(far, q, r2, f, skip);
}

KdTree3::KdTree3(const std::vector<Vec3f>& points, int leaf_size) {
  if (points.empty()) return;
  nodes_.reserve(2 * points.size() / static_cast<size_t>(std::max(1, leaf_size)) + 2);
  boxes_.reserve(nodes_.capacity());
  std::vector<Entry> entries(points.size());
  for (size_t i = 0; i < points.size(); ++i) entries[i] = {points[i], static_cast<int>(i)};
  build(entries, 0, static_cast<int>(points.size()), std::max(1, leaf_size));
  order_.resize(points.size());
  for (size_t i = 0; i < entries.size(); ++i) order_[i] = entries[i].index;
  points_.resize(points.size());
  position_.resize(points.size());
  for (auto& c : xyz_) c.reserve(points.size() + 3);
  for (size_t i = 0; i < order_.size(); ++i) {
    points_[i] = entries[i].point;
    xyz_[0].push_back(points_[i].x());
    xyz_[1].push_back(points_[i].y());
    xyz_[2].push_back(points_[i].z());
    position_[static_cast<size_t>(order_[i])] = static_cast<int>(i);
  }
  for (auto& c : xyz_) c.resize(points.size() + 3, 0.f);  // the last block of four reads whole
}

// Splits at the median of the widest extent. The entries carry their points
// (no lookup through the index); ties in the coordinate go by the input
// index, so the order is total and the tree depends on the points alone.
int KdTree3::build(std::vector<Entry>& e, int begin, int end, int leaf_size) {
  const int id = static_cast<int>(nodes_.size());
  nodes_.emplace_back();
  nodes_[static_cast<size_t>(id)].begin = begin;
  nodes_[static_cast<size_t>(id)].end = end;
  Vec3f lo = e[static_cast<size_t>(begin)].point, hi = lo;
  for (int i = begin + 1; i < end; ++i) {
    const Vec3f& p = e[static_cast<size_t>(i)].point;
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  boxes_.push_back({{lo.x(), lo.y(), lo.z()}, {hi.x(), hi.y(), hi.z()}});
  if (end - begin <= leaf_size) return id;
  int dim = 0;
  (hi - lo).maxCoeff(&dim);
  if (!(hi[dim] > lo[dim])) return id;  // all points equal: one leaf
  const int mid = begin + (end - begin) / 2;
  std::nth_element(e.begin() + begin, e.begin() + mid, e.begin() + end, [dim](const Entry& a, const Entry& b) {
    const float x = a.point[dim], y = b.point[dim];
    return x < y || (x == y && a.index < b.index);
  });
  const float split = e[static_cast<size_t>(mid)].point[dim];
  const int left = build(e, begin, mid, leaf_size);
  const int right = build(e, mid, end, leaf_size);
  Node& n = nodes_[static_cast<size_t>(id)];
  n.dim = dim;
  n.split = split;
  n.left = left;
  n.right = right;
  return id;
}

void KdTree3::nearest_in(int node, const Vec3f& q, int& best, float& best_d) const {
  const Node& n = nodes_[static_cast<size_t>(node)];
  if (n.dim < 0) {
    // Squared distances as Eigen's squaredNorm sums them (x^2 + (y^2 +
    // z^2)); only those at most the best so far are looked at.
    scan_leaf(n, q, best_d, [&](float d, int pos) {
      const int idx = order_[static_cast<size_t>(pos)];
      if (d < best_d || (d == best_d && best >= 0 && idx < best)) {
        best_d = d;
        best = idx;
      }
      return false;
    });
    return;
  }
  const float diff = q[n.dim] - n.split;
  const int near = diff < 0 ? n.left : n.right, far = diff < 0 ? n.right : n.left;
  nearest_in(near, q, best, best_d);
  if (diff * diff <= best_d) nearest_in(far, q, best, best_d);
}

int KdTree3::nearest(const Vec3f& q, float* sq_dist, float max_sq_dist, int hint) const {
  int best = -1;
  float best_d = max_sq_dist;
  if (hint >= 0 && static_cast<size_t>(hint) < position_.size()) {
    // Equal distances still reach the lower index: the pruning keeps ties.
    const float d = (points_[static_cast<size_t>(position_[static_cast<size_t>(hint)])] - q).squaredNorm();
    if (d < best_d) {
      best_d = d;
      best = hint;
    }
  }
  if (!nodes_.empty() && q.allFinite()) nearest_in(0, q, best, best_d);
  if (sq_dist) *sq_dist = best >= 0 ? best_d : std::numeric_limits<float>::infinity();
  return best;
}

// Some point other than tie_below with squared distance below `bound`, or
// equal to it with an index below tie_below. Depth first, near child
// first; a far child is skipped when the splitting plane alone is farther
// than the bound (every point beyond it is too: the float distances are
// monotonic in each coordinate's difference).
int KdTree3::any_in(int node, const Vec3f& q, float bound, int tie_below) const {
  const Node& n = nodes_[static_cast<size_t>(node)];
  if (n.dim < 0) {
    int found = -1;
    scan_leaf(n, q, bound, [&](float d, int pos) {
      const int idx = order_[static_cast<size_t>(pos)];
      // Every d here is <= bound; point tie_below itself is never one.
      if ((d < bound || idx < tie_below) && idx != tie_below) found = idx;
      return found >= 0;
    });
    return found;
  }
  const float diff = q[n.dim] - n.split;
  const int near = diff < 0 ? n.left : n.right, far = diff < 0 ? n.right : n.left;
  const int found = any_in(near, q, bound, tie_below);
  if (found >= 0 || diff * diff > bound) return found;
  return any_in(far, q, bound, tie_below);
}

int KdTree3::any_within(const Vec3f& q, float max_sq_dist, int hint) const {
  if (nodes_.empty() || !q.allFinite()) return -1;
  if (hint >= 0 && static_cast<size_t>(hint) < position_.size() &&
      (points_[static_cast<size_t>(position_[static_cast<size_t>(hint)])] - q).squaredNorm() < max_sq_dist)
    return hint;
  return any_in(0, q, max_sq_dist, -1);
}

int KdTree3::any_preferred(const Vec3f& q, int index) const {
  if (nodes_.empty() || !q.allFinite() || index < 0 || static_cast<size_t>(index) >= position_.size()) return -1;
  const float d = (points_[static_cast<size_t>(position_[static_cast<size_t>(index)])] - q).squaredNorm();
  return any_in(0, q, d, index);
}

void KdTree3::radius(const Vec3f& q, float r, std::vector<int>& out) const {
  out.clear();
  if (nodes_.empty() || !q.allFinite() || !(r > 0)) return;
  std::vector<std::pair<float, int>> found;
  auto add = [&found](float d, int i) { found.emplace_back(d, i); };
  visit_radius(0, q, r * r, add);
  std::sort(found.begin(), found.end());
  out.reserve(found.size());
  for (const auto& f : found) out.push_back(f.second);
}

namespace {

// Sorts 64-bit keys (a squared distance's float bits over a point index)
// ascending: std::sort for short lists; long ones (the neighbourhoods of
// thousands of points in noisy, dense clouds) by a bucket sort on the
// distance, then each bucket on its own. The bucket of distance d is
// floor(d * scale): non-decreasing in d (a float product with a positive
// scale and the truncation both are), so the buckets come in key order,
// and the result is std::sort's (the keys are distinct). An LSD radix sort
// of 11-bit digits takes about five passes of a count and a scattered
// write each; this makes one (after a pass for the largest distance) and
// sorts buckets of about two keys. Buckets from 64 keys on, for FPFH's
// supports of up to 256: table FPFH's hypothesize stage took 25.7 ms,
// against 27.1 ms with std::sort below 512 keys; a bound of 24 gained
// nothing more (results/bench/README.md).
// A (squared distance, index) entry as one 64-bit key: a squared distance
// is a non-negative float, whose bits order as the values do, so the key
// order is the pair order (one integer compare instead of two float ones).
inline uint64_t entry_key(float d, int i) {
  uint32_t bits;
  std::memcpy(&bits, &d, sizeof bits);
  return (static_cast<uint64_t>(bits) << 32) | static_cast<uint32_t>(i);
}
inline std::pair<float, int> entry_of(uint64_t k) {
  const uint32_t bits = static_cast<uint32_t>(k >> 32);
  float d;
  std::memcpy(&d, &bits, sizeof d);
  return {d, static_cast<int>(k & 0xffffffffu)};
}

void sort_keys(std::vector<uint64_t>& keys) {
  constexpr size_t kBucketFrom = 64;
  constexpr size_t kInsertionUpTo = 16;  // a bucket this short: insertion sort
  const size_t n = keys.size();
  const auto dist = [](uint64_t k) { return entry_of(k).first; };
  float dmax = 0;
  if (n >= kBucketFrom)
    for (uint64_t k : keys) dmax = std::max(dmax, dist(k));
  if (n < kBucketFrom || !(dmax > 1e-30f) || !std::isfinite(dmax)) {
    std::sort(keys.begin(), keys.end());
    return;
  }
  const size_t buckets = n / 2;
  const float scale = static_cast<float>(buckets) / dmax;
  const auto bucket_of = [&](uint64_t k) {
    return std::min(buckets - 1, static_cast<size_t>(dist(k) * scale));
  };
  thread_local std::vector<uint32_t> first;
  thread_local std::vector<uint64_t> tmp;
  first.assign(buckets + 1, 0u);
  tmp.resize(n);
  for (uint64_t k : keys) ++first[bucket_of(k) + 1];
  for (size_t b = 0; b < buckets; ++b) first[b + 1] += first[b];
  for (uint64_t k : keys) tmp[first[bucket_of(k)]++] = k;  // first[b] ends as bucket b's end
  uint64_t* const t = tmp.data();
  for (size_t b = 0, begin = 0; b < buckets; ++b) {
    const size_t end = first[b];
    if (end - begin > kInsertionUpTo) {
      std::sort(t + begin, t + end);
    } else {
      for (size_t i = begin + 1; i < end; ++i) {
        const uint64_t k = t[i];
        size_t j = i;
        for (; j > begin && t[j - 1] > k; --j) t[j] = t[j - 1];
        t[j] = k;
      }
    }
    begin = end;
  }
  keys.swap(tmp);
}

}  // namespace

void KdTree3::within(const Vec3f& q, float max_sq_dist, std::vector<std::pair<float, int>>& out, bool sorted) const {
  out.clear();
  if (nodes_.empty() || !q.allFinite() || !(max_sq_dist > 0)) return;
  if (!sorted) {
    auto add = [&out, max_sq_dist](float d, int i) {
      if (d < max_sq_dist) out.emplace_back(d, i);
    };
    visit_radius(0, q, max_sq_dist, add);
    return;
  }
  // Sorted by (distance, index) as one 64-bit key each (entry_key).
  thread_local std::vector<uint64_t> keys;
  keys.clear();
  auto add = [max_sq_dist](float d, int i) {
    if (d < max_sq_dist) keys.push_back(entry_key(d, i));
  };
  visit_radius(0, q, max_sq_dist, add);
  sorted_entries(keys, out);
}

void KdTree3::within_scanned(const Vec3f& q, float max_sq_dist, std::vector<std::pair<float, int>>& out) const {
  out.clear();
  if (nodes_.empty() || !q.allFinite() || !(max_sq_dist > 0)) return;
  thread_local std::vector<uint64_t> keys;
  keys.clear();
  // The root's range is every point: scanned as a leaf, in tree order (the
  // sort makes the order the tree's search's).
  scan_leaf(nodes_[0], q, max_sq_dist, [&](float d, int pos) {
    if (d < max_sq_dist) keys.push_back(entry_key(d, order_[static_cast<size_t>(pos)]));
    return false;
  });
  sorted_entries(keys, out);
}

void KdTree3::sorted_entries(std::vector<uint64_t>& keys, std::vector<std::pair<float, int>>& out) {
  sort_keys(keys);
  out.reserve(keys.size());
  for (uint64_t k : keys) out.push_back(entry_of(k));
}

void KdTree3::sort_entries(std::vector<std::pair<float, int>>& entries) {
  thread_local std::vector<uint64_t> keys;
  keys.clear();
  for (const auto& [d, i] : entries) keys.push_back(entry_key(d, i));
  sort_keys(keys);
  for (size_t k = 0; k < keys.size(); ++k) entries[k] = entry_of(keys[k]);
}

void KdTree3::radius_unsorted(const Vec3f& q, float r, std::vector<int>& out) const {
  out.clear();
  if (nodes_.empty() || !q.allFinite() || !(r > 0)) return;
  auto add = [&out](float, int i) { out.push_back(i); };
  visit_radius(0, q, r * r, add);
}

inline void KdTree3::emit(const Vec3f& q, int position, std::vector<std::pair<float, int>>& out) const {
  // The squared distance as leaf_distances computes it: x^2 + (y^2 + z^2) of
  // the point minus q.
  const size_t k = static_cast<size_t>(position);
  const float dx = xyz_[0][k] - q.x(), dy = xyz_[1][k] - q.y(), dz = xyz_[2][k] - q.z();
  out.emplace_back(dx * dx + (dy * dy + dz * dz), order_[k]);
}

// The margin of the box tests: a squared distance as leaf_distances rounds
// it is within 5 float roundings (relative 3e-7) of the exact one, so a box
// whose farthest corner is below bound x (1 - 1e-6) holds only points
// within, and one whose nearest point is beyond bound x (1 + 1e-6) none.
// Bounds this small are left to the point-by-point search (no subnormal
// rounding to reason about), and so are subtrees of fewer than kWholeFrom
// points.
constexpr double kBoxMargin = 1e-6, kSmallestBound = 1e-20;
constexpr int kWholeFrom = 8;

void KdTree3::runs_of(int node, const Vec3f& q, float bound, std::vector<Run>& runs, std::vector<int>& hits) const {
  const Node& n = nodes_[static_cast<size_t>(node)];
  if (n.end - n.begin >= kWholeFrom && bound > kSmallestBound) {
    const Box& b = boxes_[static_cast<size_t>(node)];
    double near2 = 0, far2 = 0;
    for (int d = 0; d < 3; ++d) {
      const double below = static_cast<double>(b.lo[d]) - q[d], above = static_cast<double>(q[d]) - b.hi[d];
      const double gap = std::max({below, above, 0.0}), reach = std::max(-below, -above);
      near2 += gap * gap;
      far2 += reach * reach;
    }
    if (near2 > bound * (1 + kBoxMargin)) return;  // no point within: visit_radius finds none here
    if (far2 <= bound * (1 - kBoxMargin)) {        // every point within
      runs.push_back({node, -1, n.end - n.begin});
      return;
    }
  }
  if (n.dim < 0) {
    const int first = static_cast<int>(hits.size());
    scan_leaf(n, q, bound, [&](float d, int pos) {
      if (d < bound) hits.push_back(pos);  // strictly, as within
      return false;
    });
    const int count = static_cast<int>(hits.size()) - first;
    if (count > 0) runs.push_back({node, first, count});
    return;
  }
  // The order and the pruning of visit_radius.
  const float diff = q[n.dim] - n.split;
  const int near = diff < 0 ? n.left : n.right, far = diff < 0 ? n.right : n.left;
  runs_of(near, q, bound, runs, hits);
  if (diff * diff <= bound) runs_of(far, q, bound, runs, hits);
}

void KdTree3::pick_ranks(int node, const Vec3f& q, size_t base, Ranks& ranks,
                         std::vector<std::pair<float, int>>& out) const {
  const Node& n = nodes_[static_cast<size_t>(node)];
  if (!ranks.below(base + static_cast<size_t>(n.end - n.begin))) return;  // none chosen in this subtree
  if (n.dim < 0) {
    for (; ranks.below(base + static_cast<size_t>(n.end - n.begin)); ranks.next())
      emit(q, n.begin + static_cast<int>(ranks.rank - base), out);
    return;
  }
  // Inside the ball visit_radius goes near first and visits both children.
  const float diff = q[n.dim] - n.split;
  const int near = diff < 0 ? n.left : n.right, far = diff < 0 ? n.right : n.left;
  const Node& nn = nodes_[static_cast<size_t>(near)];
  pick_ranks(near, q, base, ranks, out);
  pick_ranks(far, q, base + static_cast<size_t>(nn.end - nn.begin), ranks, out);
}

size_t KdTree3::thinned(const Vec3f& q, float bound, int max_points, std::vector<std::pair<float, int>>& out) const {
  out.clear();
  if (nodes_.empty() || !q.allFinite()) return 0;
  thread_local std::vector<Run> runs;
  thread_local std::vector<int> hits;
  runs.clear();
  hits.clear();
  runs_of(0, q, bound, runs, hits);
  size_t n = 0;
  for (const Run& r : runs) n += static_cast<size_t>(r.count);
  // keep_evenly's choice: entry floor(i n / m) of the n, i < m.
  const size_t m = max_points > 0 && n > static_cast<size_t>(max_points) ? static_cast<size_t>(max_points) : n;
  out.reserve(m);
  Ranks ranks(n, m);
  size_t start = 0;
  for (const Run& r : runs) {
    const size_t end = start + static_cast<size_t>(r.count);
    if (r.first >= 0) {
      for (; ranks.below(end); ranks.next())
        emit(q, hits[static_cast<size_t>(r.first) + (ranks.rank - start)], out);
    } else {
      pick_ranks(r.node, q, start, ranks, out);
    }
    start = end;
  }
  return n;
}

namespace {
// The count of the thread's last thinned search: a neighbourhood of at most
// kCountedFrom x max_points is found faster point by point, as within does
// (the counted runs pay their box tests and a second pass). Both ways give
// the same list; the count only picks the faster.
thread_local size_t last_found = 0;
constexpr size_t kCountedFrom = 4;

bool point_by_point(KdTree3::Thinning how, int max_points) {
  if (how != KdTree3::Thinning::automatic) return how == KdTree3::Thinning::point_by_point;
  return max_points <= 0 || last_found <= kCountedFrom * static_cast<size_t>(max_points);
}
}  // namespace

size_t KdTree3::within_thinned(const Vec3f& q, float max_sq_dist, int max_points,
                               std::vector<std::pair<float, int>>& out, Thinning how) const {
  if (point_by_point(how, max_points)) {
    within(q, max_sq_dist, out, false);
    last_found = out.size();
    keep_evenly(out, max_points);
    return last_found;
  }
  if (!(max_sq_dist > 0)) {  // as within
    out.clear();
    return last_found = 0;
  }
  return last_found = thinned(q, max_sq_dist, max_points, out);
}

// KdTree3::Remaining and radius_remaining (kdtree.h): a radius search that
// skips the points taken so far. Region growing visits every point's
// neighbourhood once; in a smooth region most of a neighbourhood is taken
// by the time it is searched, and a subtree whose points are all taken is
// not entered. The points reported are radius_unsorted's, in its order,
// without the taken ones.
KdTree3::Remaining::Remaining(const KdTree3& tree)
    : tree_(&tree),
      count_(tree.nodes_.size()),
      parent_(tree.nodes_.size(), -1),
      leaf_(tree.points_.size(), -1),
      alive_(tree.points_.size(), 1) {
  for (size_t id = 0; id < tree.nodes_.size(); ++id) {
    const Node& n = tree.nodes_[id];
    count_[id] = n.end - n.begin;
    if (n.dim < 0) {
      std::fill(leaf_.begin() + n.begin, leaf_.begin() + n.end, static_cast<int>(id));
    } else {
      parent_[static_cast<size_t>(n.left)] = static_cast<int>(id);
      parent_[static_cast<size_t>(n.right)] = static_cast<int>(id);
    }
  }
}

void KdTree3::Remaining::remove(int index) {
  const size_t pos = static_cast<size_t>(tree_->position_[static_cast<size_t>(index)]);
  if (!alive_[pos]) return;
  alive_[pos] = 0;
  for (int node = leaf_[pos]; node >= 0; node = parent_[static_cast<size_t>(node)]) --count_[static_cast<size_t>(node)];
}

// visit_radius's order and pruning; a subtree with nothing left is skipped.
void KdTree3::radius_remaining(const Vec3f& q, float r, const Remaining& left, std::vector<int>& out) const {
  out.clear();
  if (nodes_.empty() || !q.allFinite() || !(r > 0)) return;
  auto add = [&left, &out](float, int i) {
    if (left.has(i)) out.push_back(i);
  };
  visit_radius(0, q, r * r, add, [&left](int node) { return left.count_[static_cast<size_t>(node)] == 0; });
}

// KdTree3::restricted (kdtree.h): a tree over a subset of the points in
// mapped coordinates, from this tree's structure. The nodes keep their
// dimensions and children; their tree-order ranges shrink to the kept
// points (an emptied leaf is an empty range), their splits are mapped.
// Why that is a valid kd-tree: every point left of a split has its
// coordinate at most the split, every point right of it at least the split
// (the build's median), and a non-decreasing map keeps both relations.
KdTree3 KdTree3::restricted(const std::vector<size_t>& keep, const std::vector<Vec3f>& points,
                            const std::function<float(int, float)>& map) const {
  KdTree3 t;
  if (keep.empty() || nodes_.empty()) return t;
  std::vector<int> rank(order_.size(), -1);  // input index -> its k, -1 when left out
  for (size_t k = 0; k < keep.size(); ++k) rank[keep[k]] = static_cast<int>(k);
  // Kept points in this tree's order; before[pos]: how many of them precede
  // tree position pos (a node's new range is [before[begin], before[end])).
  std::vector<int> before(order_.size() + 1);
  t.order_.reserve(keep.size());
  t.points_.reserve(keep.size());
  for (size_t pos = 0; pos < order_.size(); ++pos) {
    before[pos] = static_cast<int>(t.order_.size());
    const int k = rank[static_cast<size_t>(order_[pos])];
    if (k < 0) continue;
    t.order_.push_back(k);
    t.points_.push_back(points[static_cast<size_t>(k)]);
  }
  before[order_.size()] = static_cast<int>(t.order_.size());
  t.position_.resize(t.order_.size());
  for (auto& c : t.xyz_) c.reserve(t.points_.size() + 3);
  for (size_t i = 0; i < t.order_.size(); ++i) {
    t.position_[static_cast<size_t>(t.order_[i])] = static_cast<int>(i);
    t.xyz_[0].push_back(t.points_[i].x());
    t.xyz_[1].push_back(t.points_[i].y());
    t.xyz_[2].push_back(t.points_[i].z());
  }
  for (auto& c : t.xyz_) c.resize(t.points_.size() + 3, 0.f);  // padded as a build pads them
  t.nodes_ = nodes_;
  t.boxes_.resize(nodes_.size());
  // Nodes are numbered parent before children: from the last one back, a
  // node's children are done when it is reached.
  const float inf = std::numeric_limits<float>::infinity();
  for (size_t id = t.nodes_.size(); id-- > 0;) {
    Node& n = t.nodes_[id];
    n.begin = before[static_cast<size_t>(n.begin)];
    n.end = before[static_cast<size_t>(n.end)];
    Box& b = t.boxes_[id];
    std::fill(b.lo, b.lo + 3, inf);  // an empty node: an empty box
    std::fill(b.hi, b.hi + 3, -inf);
    if (n.dim < 0) {
      for (int i = n.begin; i < n.end; ++i)
        for (int d = 0; d < 3; ++d) {
          b.lo[d] = std::min(b.lo[d], t.points_[static_cast<size_t>(i)][d]);
          b.hi[d] = std::max(b.hi[d], t.points_[static_cast<size_t>(i)][d]);
        }
      continue;
    }
    n.split = map(n.dim, n.split);
    for (const int child : {n.left, n.right}) {
      const Box& c = t.boxes_[static_cast<size_t>(child)];
      for (int d = 0; d < 3; ++d) {
        b.lo[d] = std::min(b.lo[d], c.lo[d]);
        b.hi[d] = std::max(b.hi[d], c.hi[d]);
      }
    }
  }
  return t;
}

}  // namespace pb
