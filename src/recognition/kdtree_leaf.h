// KdTree3's leaf kernel and radius traversal, shared by the .cpp files of
// the tree's searches (kdtree.cpp, kdtree_remaining.cpp): private to them.
#pragma once

#include <algorithm>
#include <cstddef>
#ifdef __SSE2__
#include <xmmintrin.h>
#endif

#include "recognition/kdtree.h"

namespace pb {

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

}  // namespace pb
