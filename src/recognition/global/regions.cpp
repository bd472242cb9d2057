// CVFH's stable regions (pcl::CVFHEstimation's algorithm, PCL-free), for
// CVFH, CESF and OUR-CVFH: high-curvature points dropped, normals
// recomputed on the rest (radius_normals: PCA about the first neighbour in
// double, PCL sums in float about the origin; from a coarse support of at
// most cvfh_normal_max_points centroids where the cloud is dense, PCL takes
// every neighbour), then smooth region growing
// (CVFH's extractEuclideanClustersSmooth): a neighbour closer than the
// tolerance joins when its normal is within the angle of the normal of the
// point that reached it. Neighbours come from the project's kd-tree in tree
// order; PCL's CVFH takes them from an unsorted FLANN tree and skips the
// first one returned, assuming it is the seed (true of a sorted search;
// here the seed is skipped because it is already processed). The angle test
// is n_seed . n_j > cos(angle), PCL's acos(n_seed . n_j) < angle without
// the arccos (a dot product rounded above 1 joins here; its arccos is NaN
// in PCL, which then leaves the point out).
#include <algorithm>
#include <cmath>

#include "recognition/global/internal.h"
#include "recognition/kdtree.h"
#include "recognition/preprocess/preprocess.h"

namespace pb::global {

std::vector<Region> stable_regions(const PointSet& cloud, const GlobalSettings& s) {
  std::vector<Region> regions;
  const size_t n = cloud.points.size();
  const bool has_c = cloud.curvature.size() == n;
  const size_t min_pts = static_cast<size_t>(std::max(s.cvfh_min_region_points, 1));

  // Step 0 (as CVFH): drop the points of high curvature.
  PointSet filtered;
  for (size_t i = 0; i < n; ++i) {
    if (!cloud.points[i].allFinite()) continue;
    if (has_c && !(cloud.curvature[i] <= s.cvfh_curvature_threshold)) continue;
    filtered.points.push_back(cloud.points[i]);
    filtered.pixel.push_back(static_cast<int>(i));  // the input index, kept through radius_normals
  }
  if (filtered.size() < min_pts) return regions;
  // Normals recomputed on the remaining points, toward the camera (origin);
  // a point with fewer than 3 neighbours has none and is dropped (in PCL its
  // NaN normal joins no region and seeds only itself).
  const double leaf = s.cvfh_normal_max_points > 0
                          ? s.cvfh_normal_radius_mm * std::sqrt(M_PI / s.cvfh_normal_max_points)
                          : 0.0;
  radius_normals(filtered, s.cvfh_normal_radius_mm, s.cvfh_normal_max_points, leaf);
  const std::vector<Vec3f>& pts = filtered.points;
  const std::vector<Vec3f>& nrm = filtered.normals;
  const KdTree3 tree(pts);

  const double cos_eps = std::cos(s.cvfh_eps_angle_deg * M_PI / 180.0);
  const float tol = static_cast<float>(s.cvfh_cluster_tolerance_mm);
  // The points not yet processed (in a region or a seed): the searches
  // report only those, in the order radius_unsorted would.
  KdTree3::Remaining unprocessed(tree);
  std::vector<int> nn, queue;
  for (size_t i = 0; i < pts.size(); ++i) {
    if (!unprocessed.has(static_cast<int>(i))) continue;
    unprocessed.remove(static_cast<int>(i));
    queue.assign(1, static_cast<int>(i));
    for (size_t q = 0; q < queue.size(); ++q) {
      const size_t seed = static_cast<size_t>(queue[q]);
      const Vec3f& ns = nrm[seed];
      tree.radius_remaining(pts[seed], tol, unprocessed, nn);
      for (const int j : nn) {
        if (static_cast<double>(ns.dot(nrm[static_cast<size_t>(j)])) > cos_eps) {
          unprocessed.remove(j);
          queue.push_back(j);
        }
      }
    }
    if (queue.size() < min_pts) continue;
    std::sort(queue.begin(), queue.end());
    Region r;
    Eigen::Vector3d c = Eigen::Vector3d::Zero(), nsum = Eigen::Vector3d::Zero();
    for (const int k : queue) {
      r.indices.push_back(filtered.pixel[static_cast<size_t>(k)]);
      r.points.push_back(pts[static_cast<size_t>(k)]);
      r.normals.push_back(nrm[static_cast<size_t>(k)]);
      c += pts[static_cast<size_t>(k)].cast<double>();
      nsum += nrm[static_cast<size_t>(k)].cast<double>();
    }
    r.centroid = (c / static_cast<double>(queue.size())).cast<float>();
    if (nsum.norm() > 0) r.mean_normal = nsum.normalized().cast<float>();
    regions.push_back(std::move(r));
  }
  return regions;
}

}  // namespace pb::global
