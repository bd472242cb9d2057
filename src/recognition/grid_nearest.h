// Exact nearest-neighbour queries within a bound on a dense uniform grid,
// PCL-free: the same answers as KdTree3::nearest (kdtree.h), bit for bit,
// for the searches whose bound is about one cell (ICP's correspondences and
// fitness, where every query has a bound of max_correspondence and most a
// hint: the previous iteration's match). The answer of both is the point of
// smallest squared distance strictly below the bound, computed as
// x^2 + (y^2 + z^2) of the point minus the query in float, equal distances
// going to the lower point index. A query looks only at the cells that the
// ball of the bound (or of the hint's distance, when smaller) overlaps,
// widened by a margin that covers the distances' rounding: about one to eight
// cells of a few points each, where the kd-tree descends from its root.
// Queries whose box spans many cells (no hint and a large bound) go to a
// kd-tree kept beside the grid. Const and thread-safe.
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include "core/types.h"
#include "recognition/kdtree.h"

namespace pb {

class GridNearest {
 public:
  GridNearest() = default;
  // A grid of cubic cells of side `cell` (the bound the queries will
  // mostly have; larger if the points' box would need more than 2^22
  // cells) over the finite points, and a kd-tree over them. Queries whose
  // box spans more than three cells on an axis go to the kd-tree, and all
  // of them do when the cells would hold more than 8 points on average (a
  // surface sampled densely for the bound's size: the warehouse). Neither
  // changes an answer.
  GridNearest(const std::vector<Vec3f>& points, double cell);

  // The nearest point with squared distance below max_sq_dist (index, or -1
  // when none); its squared distance in *sq_dist (infinity when none).
  // `hint` (an input index, or -1): a point likely near q; it only narrows
  // the cells looked at, the answer is the same.
  int nearest(const Vec3f& q, float* sq_dist = nullptr,
              float max_sq_dist = std::numeric_limits<float>::infinity(), int hint = -1) const;
  size_t size() const { return index_of_.size(); }
  double cell_side() const { return 1.0 / inv_; }
  bool has_grid() const { return grid_; }

 private:
  double origin_[3] = {0, 0, 0};
  double inv_ = 1;         // 1 / cell side
  double scale_ = 1;       // 1 + the largest coordinate magnitude (rounding margin)
  int dims_[3] = {0, 0, 0};
  std::vector<uint32_t> start_;     // per cell (x fastest), its first slot; one more at the end
  std::vector<float> x_, y_, z_;    // the finite points, cell by cell
  std::vector<int> index_;          // slot -> input index
  std::vector<int> index_of_;       // input index -> slot, or -1 (not finite)
  KdTree3 tree_;                    // the queries whose box spans many cells
  bool grid_ = false;               // false: every query goes to tree_
};

}  // namespace pb
