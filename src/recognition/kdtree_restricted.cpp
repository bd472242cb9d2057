// KdTree3::restricted (kdtree.h): a tree over a subset of the points in
// mapped coordinates, from this tree's structure. The nodes keep their
// dimensions and children; their tree-order ranges shrink to the kept
// points (an emptied leaf is an empty range), their splits are mapped.
// Why that is a valid kd-tree: every point left of a split has its
// coordinate at most the split, every point right of it at least the split
// (the build's median), and a non-decreasing map keeps both relations.
#include <algorithm>
#include <limits>

#include "recognition/kdtree.h"

namespace pb {

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
