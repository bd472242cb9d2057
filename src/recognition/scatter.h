// The scatter matrix sum_k w_k d_k d_k^T of 3D offsets, accumulated as its
// six distinct entries in double (d_i d_j == d_j d_i exactly), each summed
// in the order the offsets are added. The same sums, bit for bit, as the
// lower triangle of Eigen's `S += d * d.transpose()` (or `w * (...)`, see
// add_weighted) over the full 3x3, at a third of the work.
// Used by every PCA of a point set: normals (preprocessing, refinement),
// the plane fit, the SHOT and BOARD frames.
#pragma once

#include "core/types.h"

namespace pb {

struct Scatter3 {
  double xx = 0, xy = 0, xz = 0, yy = 0, yz = 0, zz = 0;

  void add(double dx, double dy, double dz) {
    xx += dx * dx;
    xy += dx * dy;
    xz += dx * dz;
    yy += dy * dy;
    yz += dy * dz;
    zz += dz * dz;
  }
  void add(const Vec3& d) { add(d.x(), d.y(), d.z()); }
  // w d d^T as Eigen's `w * (d * d.transpose())` computes its lower
  // triangle, (w d_i) d_j for i >= j (its upper triangle, (w d_j) d_i, may
  // differ in the last bit; a self-adjoint eigensolver reads the lower one).
  void add_weighted(double w, const Vec3& d) {
    const double wx = w * d.x(), wy = w * d.y(), wz = w * d.z();
    xx += wx * d.x();
    xy += wy * d.x();
    xz += wz * d.x();
    yy += wy * d.y();
    yz += wz * d.y();
    zz += wz * d.z();
  }
  Mat3 matrix() const {
    Mat3 m;
    m << xx, xy, xz, xy, yy, yz, xz, yz, zz;
    return m;
  }
};

}  // namespace pb
