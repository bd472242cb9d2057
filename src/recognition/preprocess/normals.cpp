// Normals of the preprocessed cloud through pcl::NormalEstimationOMP (PCA of
// the neighbours in a radius, flipped toward the viewpoint at the origin).
// OpenMP computes each point independently, so the result does not depend on
// the thread count.
#include <pcl/features/normal_3d_omp.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>

#include <cmath>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "recognition/pcl_adapter.h"
#include "recognition/preprocess/internal.h"

#include <pcl/console/print.h>

namespace {
// PCL's messages (OUR-CVFH's "both axes are equally easy/difficult to
// disambiguate", CVFH's "no clusters were found", the RANSAC inside Hough
// grouping's "no samples could be selected") would flood stderr and the
// runner's worker log. Every PCL result is checked by its caller instead.
struct QuietPcl {
  QuietPcl() { pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS); }
} quiet_pcl;
}  // namespace

namespace pb::detail {

void estimate_normals(PointSet& ps, double radius_mm) {
  ps.normals.clear();
  ps.curvature.clear();
  if (ps.points.empty()) return;
  const auto cloud = pcl_adapter::xyz(ps.points);
  pcl::NormalEstimationOMP<pcl::PointXYZ, pcl::Normal> ne;
#ifdef _OPENMP
  ne.setNumberOfThreads(static_cast<unsigned>(omp_get_max_threads()));
#else
  ne.setNumberOfThreads(1);
#endif
  ne.setInputCloud(cloud);
  ne.setSearchMethod(pcl::search::KdTree<pcl::PointXYZ>::Ptr(new pcl::search::KdTree<pcl::PointXYZ>));
  ne.setRadiusSearch(radius_mm);
  ne.setViewPoint(0.f, 0.f, 0.f);
  pcl::PointCloud<pcl::Normal> normals;
  ne.compute(normals);

  std::vector<char> keep(ps.points.size(), 0);
  ps.normals.resize(ps.points.size(), Vec3f::Zero());
  ps.curvature.resize(ps.points.size(), 0.f);
  size_t kept = 0;
  for (size_t i = 0; i < ps.points.size(); ++i) {
    const pcl::Normal& n = normals[i];
    if (!std::isfinite(n.normal_x) || !std::isfinite(n.normal_y) || !std::isfinite(n.normal_z) ||
        !std::isfinite(n.curvature))
      continue;
    Vec3f v(n.normal_x, n.normal_y, n.normal_z);
    const float l = v.norm();
    if (!(l > 0.f)) continue;
    ps.normals[i] = v / l;
    ps.curvature[i] = n.curvature;
    keep[i] = 1;
    ++kept;
  }
  if (kept != ps.points.size()) ps = select(ps, keep);
}

}  // namespace pb::detail
