// Normals of the preprocessed cloud: PCA of the neighbours within a radius
// (the point itself included; as pcl::NormalEstimation), the eigenvector of
// the smallest eigenvalue of their covariance, flipped toward the viewpoint
// at the origin; curvature = the surface variation l0 / (l0 + l1 + l2).
// Neighbours come from the project's kd-tree (kdtree.h), built once; the
// covariance is accumulated in double about the neighbourhood's first point
// (stable for clouds far from the origin). Each point is independent, so
// OpenMP threads do not change the result.
#include <Eigen/Eigenvalues>
#include <cmath>

#include "recognition/kdtree.h"
#include "recognition/preprocess/internal.h"
#include "recognition/scatter.h"

namespace pb::detail {

namespace {

// Normal and curvature of one neighbourhood; false when fewer than 3 points
// or degenerate.
bool pca_normal(const std::vector<Vec3f>& pts, const std::vector<int>& nb, Vec3f& normal, float& curvature) {
  if (nb.size() < 3) return false;
  const Vec3f& o = pts[static_cast<size_t>(nb[0])];
  const double ox = o.x(), oy = o.y(), oz = o.z();
  double sx = 0, sy = 0, sz = 0;
  Scatter3 sq;
  for (int j : nb) {
    const Vec3f& p = pts[static_cast<size_t>(j)];
    const double dx = static_cast<double>(p.x()) - ox, dy = static_cast<double>(p.y()) - oy,
                 dz = static_cast<double>(p.z()) - oz;
    sx += dx;
    sy += dy;
    sz += dz;
    sq.add(dx, dy, dz);
  }
  const double n = static_cast<double>(nb.size());
  const Vec3 mean = Vec3(sx, sy, sz) / n;
  const Mat3 cov = sq.matrix() / n - mean * mean.transpose();
  Eigen::SelfAdjointEigenSolver<Mat3> es;
  es.computeDirect(cov);
  const Vec3 ev = es.eigenvalues();
  const Vec3 v = es.eigenvectors().col(0);
  if (!v.allFinite() || !(v.norm() > 0)) return false;
  normal = v.normalized().cast<float>();
  const double total = ev.sum();
  curvature = total != 0 ? static_cast<float>(std::abs(ev[0] / total)) : 0.f;
  return true;
}

}  // namespace

void estimate_normals(PointSet& ps, double radius_mm, int max_points) {
  ps.normals.clear();
  ps.curvature.clear();
  if (ps.points.empty()) return;
  const KdTree3 tree(ps.points);
  const long n = static_cast<long>(ps.points.size());
  std::vector<char> keep(ps.points.size(), 0);
  ps.normals.assign(ps.points.size(), Vec3f::Zero());
  ps.curvature.assign(ps.points.size(), 0.f);
#pragma omp parallel
  {
    std::vector<int> nb;
#pragma omp for schedule(static)
    for (long i = 0; i < n; ++i) {
      const size_t k = static_cast<size_t>(i);
      tree.radius_unsorted(ps.points[k], static_cast<float>(radius_mm), nb);
      keep_evenly(nb, max_points);
      Vec3f nrm;
      float curv = 0;
      if (!pca_normal(ps.points, nb, nrm, curv)) continue;
      if (nrm.dot(-ps.points[k]) < 0) nrm = -nrm;  // toward the viewpoint (origin)
      ps.normals[k] = nrm;
      ps.curvature[k] = curv;
      keep[k] = 1;
    }
  }
  size_t kept = 0;
  for (char c : keep) kept += c;
  if (kept != ps.points.size()) ps = select(ps, keep);
}

}  // namespace pb::detail
