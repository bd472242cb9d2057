// A static kd-tree over 3D points, PCL-free: built once per cloud, exact
// nearest-neighbour and radius queries, const and thread-safe, deterministic
// (equal distances resolve to the lower point index). Used wherever the
// pipeline searches a cloud many times: refinement (one tree per scene crop
// and per model cloud, not one per ICP iteration), verification, normals.
#pragma once

#include <functional>
#include <limits>
#include <utility>
#include <vector>

#include "core/types.h"

namespace pb {

class KdTree3 {
 public:
  KdTree3() = default;
  explicit KdTree3(const std::vector<Vec3f>& points, int leaf_size = 8);

  // The nearest point with squared distance below max_sq_dist (index, or -1
  // when none); its squared distance in *sq_dist. `hint` (an input index, or
  // -1), a point likely near q (ICP: the previous iteration's match), only
  // tightens the search bound from the start: the answer is the same.
  int nearest(const Vec3f& q, float* sq_dist = nullptr,
              float max_sq_dist = std::numeric_limits<float>::infinity(), int hint = -1) const;
  // Some point with squared distance below max_sq_dist (index, or -1 when
  // none): `hint` (an input index, or -1) if it is one, else the first the
  // search meets. Whether there is one is what nearest() tells; which one it
  // returns is not the nearest, and the search ends at it (an inlier count,
  // a reciprocity check: a yes/no question).
  int any_within(const Vec3f& q, float max_sq_dist, int hint = -1) const;
  // Some point that nearest(q) would prefer to input point `index` (nearer
  // to q, or as near with a lower index), -1 if none: then nearest(q, ...,
  // index) is `index` (when within its bound). Ends at the first one found.
  int any_preferred(const Vec3f& q, int index) const;
  // Every point within r (squared distance <= r^2), sorted by distance, then
  // index.
  void radius(const Vec3f& q, float r, std::vector<int>& out) const;
  // Every point with squared distance below max_sq_dist (strictly, as
  // FLANN's radius search), as (squared distance, index), sorted unless
  // `sorted` is false (then in tree order).
  void within(const Vec3f& q, float max_sq_dist, std::vector<std::pair<float, int>>& out, bool sorted = true) const;
  // The sorted list of within(q, max_sq_dist, out), found by scanning every
  // point (the leaves' distances, the same sort) instead of the tree: the
  // same list, cheaper where a query lists a large part of a small cloud.
  void within_scanned(const Vec3f& q, float max_sq_dist, std::vector<std::pair<float, int>>& out) const;
  // The same set in tree order (no sort: for sums over the neighbourhood).
  void radius_unsorted(const Vec3f& q, float r, std::vector<int>& out) const;
  // The points a search still reports (region growing: those no region has
  // taken yet), counted per node so that a search skips a subtree with none
  // left. Starts with every point of `tree`, which must outlive it.
  class Remaining {
   public:
    explicit Remaining(const KdTree3& tree);
    bool has(int index) const { return alive_[static_cast<size_t>(tree_->position_[static_cast<size_t>(index)])] != 0; }
    void remove(int index);  // an input index; nothing when already removed

   private:
    friend class KdTree3;
    const KdTree3* tree_;
    std::vector<int> count_;   // per node: points left in its subtree
    std::vector<int> parent_;  // per node (-1: the root)
    std::vector<int> leaf_;    // per tree position: its leaf
    std::vector<char> alive_;  // per tree position
  };
  // radius_unsorted without the points `left` no longer has: the others in
  // the same order.
  void radius_remaining(const Vec3f& q, float r, const Remaining& left, std::vector<int>& out) const;
  // The list of within(q, max_sq_dist, out, false) thinned by
  // keep_evenly(out, max_points), the same entries in the same order, and
  // how many points were within (before thinning). Counted: without
  // visiting every point of a large neighbourhood (FPFH's supports): a
  // subtree whose box lies inside the ball (with a margin that covers the
  // distances' rounding) is counted whole and only its chosen points are
  // looked up, by rank; one outside it is skipped. Point by point: within,
  // then keep_evenly (faster for small neighbourhoods). Automatic: counted
  // where the thread's last such search found more than 4 x max_points.
  enum class Thinning { automatic, counted, point_by_point };
  size_t within_thinned(const Vec3f& q, float max_sq_dist, int max_points, std::vector<std::pair<float, int>>& out,
                        Thinning how = Thinning::automatic) const;
  size_t size() const { return points_.size(); }
  // This tree cut down to some of its points, in other coordinates, without
  // a new build: input point keep[k] (ascending input indices) becomes
  // point k of the result, at points[k]; the others are left out. The new
  // coordinates must be the old ones mapped axis by axis by map(axis, x),
  // non-decreasing in x (a shift and a scale, rounded: refinement's local
  // frame). The splits are mapped by it and the boxes taken over the kept
  // points, so the result is a kd-tree over `points`: nearest and the any_
  // queries answer as on KdTree3(points), radius and within list the same
  // points (the unsorted orders differ). O(size) where a build is
  // O(size log size).
  KdTree3 restricted(const std::vector<size_t>& keep, const std::vector<Vec3f>& points,
                     const std::function<float(int, float)>& map) const;
  // Sorts (squared distance, index) entries as std::sort does (distance,
  // then index), where every distance is a non-negative float and every
  // index non-negative (what within() lists): as 64-bit keys, as within().
  static void sort_entries(std::vector<std::pair<float, int>>& entries);

 private:
  struct Node {
    int begin = 0, end = 0;   // range of order_ / points_ (a leaf when dim < 0)
    int dim = -1;
    float split = 0;
    int left = -1, right = -1;
  };
  struct Box {
    float lo[3], hi[3];  // of a node's points
  };
  // A run of the radius search's visiting order: a subtree inside the ball
  // (first < 0: every point of `node`) or the points of a leaf found within
  // (tree positions hits[first, first + count)).
  struct Run {
    int node, first, count;
  };
  void runs_of(int node, const Vec3f& q, float bound, std::vector<Run>& runs,
               std::vector<int>& hits) const;
  size_t thinned(const Vec3f& q, float bound, int max_points, std::vector<std::pair<float, int>>& out) const;
  // keep_evenly's choice of n entries as a stream of ranks: floor(i n / m)
  // for i < m, stepped without division.
  struct Ranks {
    size_t i = 0, m = 0, rank = 0, rem = 0, step = 0, extra = 0;
    Ranks(size_t n, size_t keep) : m(keep), step(keep ? n / keep : 0), extra(keep ? n % keep : 0) {}
    bool below(size_t end) const { return i < m && rank < end; }
    void next() {
      ++i;
      rank += step;
      rem += extra;
      if (rem >= m) {
        rem -= m;
        ++rank;
      }
    }
  };
  // Appends the subtree's points whose ranks come next (its points take
  // ranks base.. in visit_radius's order: near child first) as (squared
  // distance, input index).
  void pick_ranks(int node, const Vec3f& q, size_t base, Ranks& ranks, std::vector<std::pair<float, int>>& out) const;
  void emit(const Vec3f& q, int position, std::vector<std::pair<float, int>>& out) const;
  struct Entry {
    Vec3f point;
    int index;  // in the input
  };
  int build(std::vector<Entry>& entries, int begin, int end, int leaf_size);
  void nearest_in(int node, const Vec3f& q, int& best, float& best_d) const;
  int any_in(int node, const Vec3f& q, float bound, int tie_below) const;
  // Squared distances from q of the m <= 4 points at tree positions i..i+m
  // into d4 (as Eigen's squaredNorm computes them); bit k of the result: the
  // k-th is at most `bound`.
  int leaf_distances(const Vec3f& q, int i, int m, float bound, float* d4) const;
  // Calls f(squared distance, tree position) for each point of leaf `n` at
  // most `bound` from q, in tree order, four distances at a time; `bound` is
  // read again for every four, so f may lower it. f returns true to stop the
  // scan; then so does scan_leaf.
  template <class F>
  bool scan_leaf(const Node& n, const Vec3f& q, const float& bound, F&& f) const;
  // within()'s keys (entry_key) sorted into out, as (distance, index).
  static void sorted_entries(std::vector<uint64_t>& keys, std::vector<std::pair<float, int>>& out);
  // Calls f(squared distance, input index) for every point within sqrt(r2)
  // of the subtrees for which skip(node) is false.
  struct NoSkip {
    bool operator()(int) const { return false; }
  };
  template <class F, class Skip = NoSkip>
  void visit_radius(int node, const Vec3f& q, float r2, F& f, const Skip& skip = Skip()) const;

  std::vector<Vec3f> points_;  // in tree order (cache friendly)
  std::vector<float> xyz_[3];  // the same, one array per coordinate (four at a time)
  std::vector<int> order_;     // tree position -> input index
  std::vector<int> position_;  // input index -> tree position
  std::vector<Node> nodes_;
  std::vector<Box> boxes_;  // per node (apart from nodes_: the nearest search reads nodes_ alone)
};

// Thins a neighbour list to at most `max_points` entries evenly spaced in
// its order (entry floor(i * n / max_points) for i < max_points): in order
// of distance a sample even in rank, in tree order a spatially stratified
// one. No random draw, so the same list gives the same sample. 0 keeps all.
template <class T>
void keep_evenly(std::vector<T>& v, int max_points) {
  const size_t n = v.size();
  if (max_points <= 0 || n <= static_cast<size_t>(max_points)) return;
  const size_t m = static_cast<size_t>(max_points);
  for (size_t i = 0; i < m; ++i) v[i] = v[i * n / m];  // i * n / m >= i: reads ahead of writes
  v.resize(m);
}

}  // namespace pb
