// Normals of the preprocessed cloud: PCA of the neighbours within a radius
// (the point itself included; as pcl::NormalEstimation), the eigenvector of
// the smallest eigenvalue of their covariance, flipped toward the viewpoint
// at the origin; curvature = the surface variation l0 / (l0 + l1 + l2).
// Neighbours come from the project's kd-tree (kdtree.h), built once; the
// covariance is accumulated in double about the neighbourhood's first point
// (stable for clouds far from the origin). Each point is independent, so
// OpenMP threads do not change the result.
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "recognition/kdtree.h"
#include "recognition/preprocess/internal.h"
#include "recognition/preprocess/preprocess.h"
#include "recognition/preprocess/voxel_grid.h"
#include "recognition/scatter.h"

namespace pb {

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

void radius_normals(PointSet& ps, double radius_mm, int max_points, double support_leaf_mm) {
  ps.normals.clear();
  ps.curvature.clear();
  if (ps.points.empty()) return;
  const long n = static_cast<long>(ps.points.size());
  const float r = static_cast<float>(radius_mm);
  std::vector<char> keep(ps.points.size(), 0), fine(ps.points.size(), 1);
  ps.normals.assign(ps.points.size(), Vec3f::Zero());
  ps.curvature.assign(ps.points.size(), 0.f);
  // One point's normal from the neighbours `nb` (indices into `pts`).
  auto set_normal = [&](size_t k, const std::vector<Vec3f>& pts, const std::vector<int>& nb) {
    Vec3f nrm;
    float curv = 0;
    if (!pca_normal(pts, nb, nrm, curv)) return false;
    if (nrm.dot(-ps.points[k]) < 0) nrm = -nrm;  // toward the viewpoint (origin)
    ps.normals[k] = nrm;
    ps.curvature[k] = curv;
    keep[k] = 1;
    return true;
  };
  if (support_leaf_mm > 0) {  // first from the coarse support: the cloud's centroids at support_leaf_mm
    PointSet bare;
    bare.points = ps.points;
    const PointSet support = voxel_downsample(bare, {support_leaf_mm});
    const KdTree3 coarse(support.points);
    const size_t min_coarse = static_cast<size_t>(std::max(3, max_points / 4));
#pragma omp parallel
    {
      std::vector<int> nb;
#pragma omp for schedule(static)
      for (long i = 0; i < n; ++i) {
        const size_t k = static_cast<size_t>(i);
        coarse.radius_unsorted(ps.points[k], r, nb);
        if (nb.size() < min_coarse) continue;  // sparse here: the fine neighbourhood below
        keep_evenly(nb, max_points);
        fine[k] = !set_normal(k, support.points, nb);
      }
    }
  }
  const size_t n_fine = static_cast<size_t>(std::count(fine.begin(), fine.end(), 1));
  if (n_fine > 0 && n_fine <= 64 && support_leaf_mm > 0) {
    // A few sparse points: their neighbours by a scan (cheaper than a tree).
    const float r2 = r * r;
    std::vector<int> nb;
    for (size_t k = 0; k < ps.points.size(); ++k) {
      if (!fine[k]) continue;
      nb.clear();
      for (size_t j = 0; j < ps.points.size(); ++j)
        if ((ps.points[j] - ps.points[k]).squaredNorm() <= r2) nb.push_back(static_cast<int>(j));
      keep_evenly(nb, max_points);
      set_normal(k, ps.points, nb);
    }
  } else if (n_fine > 0) {
    const KdTree3 tree(ps.points);
#pragma omp parallel
    {
      std::vector<int> nb;
#pragma omp for schedule(static)
      for (long i = 0; i < n; ++i) {
        const size_t k = static_cast<size_t>(i);
        if (!fine[k]) continue;
        tree.radius_unsorted(ps.points[k], r, nb);
        keep_evenly(nb, max_points);
        set_normal(k, ps.points, nb);
      }
    }
  }
  size_t kept = 0;
  for (char c : keep) kept += c;
  if (kept != ps.points.size()) ps = detail::select(ps, keep);
}

}  // namespace pb
