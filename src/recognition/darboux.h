// The Darboux-frame features of a pair of oriented points (Rusu et al.'s
// PFH pair features, pcl::computePairFeatures), shared by FPFH
// (local/fpfh.cpp) and VFH (global/vfh.cpp). Differences from PCL, both at
// rounding level: the source point is chosen by comparing |cos| instead of
// the arccos of each, and the dot products are summed over three
// coordinates instead of four.
#pragma once

#include <algorithm>
#include <cmath>

#include "core/types.h"

namespace pb {

// The pair features of (p1, n1) and (p2, n2): false when the points coincide
// or the frame is degenerate. The source is the point whose normal is closer
// to the line between them (smaller angle: larger |cos|). *symmetric: the
// call (p2, p1) gives bit-identical features (and the same return value):
// both cosines finite and of different magnitude, so both calls pick the
// same source point and compute the same frame from exactly negated inputs.
// f1 = atan2(*f1_y, *f1_x): its arguments (binned without atan2f where the
// bin is in no doubt, core/atan2_bin.h); f2 = v . n_target; f3 = the source
// normal's cosine to the line; *dist (if given) = |p2 - p1| (PCL's f4).
inline bool darboux_pair(const Vec3f& p1, const Vec3f& n1, const Vec3f& p2, const Vec3f& n2, float* f1_y,
                         float* f1_x, float& f2, float& f3, bool* symmetric, float* dist_out = nullptr) {
  Vec3f d = p2 - p1;
  const float dist = d.norm();
  if (dist_out) *dist_out = dist;
  *symmetric = false;
  if (dist == 0.f) return false;
  const float c1 = n1.dot(d) / dist, c2 = n2.dot(d) / dist;
  *symmetric = std::isfinite(c1) && std::isfinite(c2) && std::abs(c1) != std::abs(c2);
  Vec3f u = n1, target = n2;
  f3 = c1;
  if (std::abs(c1) < std::abs(c2)) {
    u = n2;
    target = n1;
    d = -d;
    f3 = -c2;
  }
  Vec3f v = d.cross(u);
  const float vn = v.norm();
  if (vn == 0.f) return false;
  v /= vn;
  const Vec3f w = u.cross(v);
  f2 = v.dot(target);
  *f1_y = w.dot(target);
  *f1_x = u.dot(target);
  return true;
}

// A pair feature's bin: floor(scaled) clamped to [0, bins - 1], a NaN in
// bin 0 (PCL's floor in double, clamped; a NaN lands in bin 0 as PCL's
// clamped conversion does on x86). FPFH and VFH bin their features so.
inline int clamped_bin(double scaled, int bins) {
  if (!(scaled >= 0)) return 0;
  return std::min(static_cast<int>(std::floor(scaled)), bins - 1);
}

}  // namespace pb
