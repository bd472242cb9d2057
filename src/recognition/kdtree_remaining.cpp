// KdTree3::Remaining and radius_remaining (kdtree.h): a radius search that
// skips the points taken so far. Region growing visits every point's
// neighbourhood once; in a smooth region most of a neighbourhood is taken
// by the time it is searched, and a subtree whose points are all taken is
// not entered. The points reported are radius_unsorted's, in its order,
// without the taken ones.
#include <algorithm>

#include "recognition/kdtree.h"
#include "recognition/kdtree_leaf.h"

namespace pb {

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

}  // namespace pb
