// KdTree3's leaf kernel, shared by the .cpp files of the tree's searches
// (kdtree.cpp, kdtree_remaining.cpp): private to them.
#pragma once

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

}  // namespace pb
