// PCL's CVFH pieces, the references of the project's own (tests only):
// pcl::CVFHEstimation (cvfh.cpp), pcl::VFHEstimation from a given centroid
// and normal (vfh_histogram), and CVFH's stable regions grown by PCL's code
// on a sorted or unsorted FLANN tree (regions.cpp).
#include <pcl/features/cvfh.h>
#include <pcl/features/normal_3d.h>
#include <pcl/features/vfh.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "recognition/global/internal.h"
#include "recognition/global/pcl_cvfh.h"

namespace pb::global {

std::vector<Signature> cvfh_signatures_pcl(const PointSet& cloud, const GlobalSettings& s) {
  std::vector<Signature> out;
  if (!cloud.has_normals()) return out;
  const PclInput in = pcl_input(cloud, 1.0f, false);
  // VFH needs a few points to be meaningful (and PCL's estimators misbehave
  // on near-empty input).
  if (in.points->size() < 10) return out;

  pcl::CVFHEstimation<pcl::PointXYZ, pcl::Normal, pcl::VFHSignature308> cvfh;
  configure_cvfh_family(cvfh, in, s, 1.0f);
  pcl::PointCloud<pcl::VFHSignature308> sigs;
  cvfh.compute(sigs);

  std::vector<Eigen::Vector3f, Eigen::aligned_allocator<Eigen::Vector3f>> centroids, normals;
  cvfh.getCentroidClusters(centroids);
  cvfh.getCentroidNormalClusters(normals);
  const bool with_normals = normals.size() == sigs.size();
  for (size_t k = 0; k < sigs.size() && k < centroids.size(); ++k) {
    Signature sig;
    sig.hist.assign(sigs[k].histogram, sigs[k].histogram + 308);
    bool finite = true;
    for (float v : sig.hist) finite = finite && std::isfinite(v);
    if (!finite) continue;
    sig.centroid = centroids[k];
    if (with_normals && normals[k].allFinite() && normals[k].norm() > 0.5f) {
      sig.axis = -normals[k].normalized();
      sig.from_normal = true;
    } else {
      sig.axis = centroids[k].normalized();
    }
    out.push_back(std::move(sig));
  }
  return out;
}

std::vector<float> vfh_histogram_pcl(const std::vector<Vec3f>& points, const std::vector<Vec3f>& normals,
                                     const Vec3f& centroid, const Vec3f& normal, bool normalize_bins) {
  PointSet cloud;
  cloud.points = points;
  cloud.normals = normals;
  const PclInput in = pcl_input(cloud, 1.0f, false);
  pcl::VFHEstimation<pcl::PointXYZ, pcl::Normal, pcl::VFHSignature308> vfh;
  vfh.setInputCloud(in.points);
  vfh.setInputNormals(in.normals);
  vfh.setSearchMethod(pcl::search::KdTree<pcl::PointXYZ>::Ptr(new pcl::search::KdTree<pcl::PointXYZ>));
  vfh.setUseGivenNormal(true);
  vfh.setUseGivenCentroid(true);
  vfh.setNormalToUse(normal);
  vfh.setCentroidToUse(centroid);
  vfh.setNormalizeBins(normalize_bins);
  vfh.setNormalizeDistance(true);
  vfh.setFillSizeComponent(true);
  pcl::PointCloud<pcl::VFHSignature308> sig;
  vfh.compute(sig);
  return std::vector<float>(sig[0].histogram, sig[0].histogram + 308);
}

namespace {

using PointNormalCloud = pcl::PointCloud<pcl::PointNormal>;
using PointNormalTree = pcl::search::KdTree<pcl::PointNormal>;

// Step 0 (as CVFH): the finite points without the ones of high curvature,
// normals zero.
PointNormalCloud::Ptr low_curvature_points(const PointSet& cloud, const GlobalSettings& s) {
  const size_t n = cloud.points.size();
  const bool has_c = cloud.curvature.size() == n;
  PointNormalCloud::Ptr filtered(new PointNormalCloud);
  for (size_t i = 0; i < n; ++i) {
    if (!cloud.points[i].allFinite()) continue;
    if (has_c && !(cloud.curvature[i] <= s.cvfh_curvature_threshold)) continue;
    pcl::PointNormal p;
    p.getVector3fMap() = cloud.points[i];
    p.getNormalVector3fMap() = Vec3f::Zero();
    p.curvature = 0;
    filtered->push_back(p);
  }
  return filtered;
}

// Normals recomputed on the points, toward the camera (origin).
void recompute_normals(const PointNormalCloud::Ptr& points, const GlobalSettings& s) {
  PointNormalTree::Ptr tree(new PointNormalTree(false));
  tree->setInputCloud(points);
  pcl::NormalEstimation<pcl::PointNormal, pcl::PointNormal> ne;
  ne.setRadiusSearch(s.cvfh_normal_radius_mm);
  ne.setSearchMethod(tree);
  ne.setInputCloud(points);
  ne.setViewPoint(0.f, 0.f, 0.f);
  ne.compute(*points);
}

// One smooth region grown from point i (CVFH's
// extractEuclideanClustersSmooth): a neighbour within the tolerance joins
// when its normal is within the angle of the normal of the point that
// reached it. Its points (marked processed), in the order they joined.
std::vector<int> grow_smooth_region(const PointNormalCloud& points, const PointNormalTree& tree, size_t i, float tol,
                                    double eps, std::vector<char>& processed) {
  pcl::Indices nn;
  std::vector<float> nd;
  processed[i] = 1;
  std::vector<int> queue{static_cast<int>(i)};
  for (size_t q = 0; q < queue.size(); ++q) {
    const int seed = queue[q];
    const Vec3f ns = points[seed].getNormalVector3fMap();
    if (!ns.allFinite()) continue;
    if (tree.radiusSearch(seed, tol, nn, nd) <= 0) continue;
    // As PCL's CVFH, the first neighbour returned is skipped (it assumes
    // it is the seed itself, which an unsorted search does not promise);
    // kept so the regions are exactly CVFH's.
    for (size_t jj = 1; jj < nn.size(); ++jj) {
      const auto j = nn[jj];
      if (processed[j]) continue;
      const Vec3f nj = points[j].getNormalVector3fMap();
      const double dot = ns.dot(nj);
      if (std::acos(std::clamp(dot, -1.0, 1.0)) < eps && nj.allFinite()) {
        processed[j] = 1;
        queue.push_back(j);
      }
    }
  }
  return queue;
}

// The region of the given points (ascending indices): their points and
// normals, centroid and mean normal.
Region region_of(const PointNormalCloud& points, const std::vector<int>& members) {
  Region r;
  Eigen::Vector3d c = Eigen::Vector3d::Zero(), nsum = Eigen::Vector3d::Zero();
  for (int k : members) {
    const auto& p = points[k];
    r.points.push_back(p.getVector3fMap());
    r.normals.push_back(p.getNormalVector3fMap());
    c += p.getVector3fMap().cast<double>();
    nsum += p.getNormalVector3fMap().cast<double>();
  }
  r.centroid = (c / static_cast<double>(members.size())).cast<float>();
  if (nsum.norm() > 0) r.mean_normal = nsum.normalized().cast<float>();
  return r;
}

}  // namespace

std::vector<Region> stable_regions_pcl(const PointSet& cloud, const GlobalSettings& s, bool sorted) {
  std::vector<Region> regions;
  const size_t min_pts = static_cast<size_t>(std::max(s.cvfh_min_region_points, 1));
  const PointNormalCloud::Ptr filtered = low_curvature_points(cloud, s);
  if (filtered->size() < min_pts) return regions;
  recompute_normals(filtered, s);
  // The tree of the region growing: PCL's CVFH builds it unsorted.
  PointNormalTree::Ptr tree(new PointNormalTree(sorted));
  tree->setInputCloud(filtered);
  const double eps = s.cvfh_eps_angle_deg * M_PI / 180.0;
  const float tol = static_cast<float>(s.cvfh_cluster_tolerance_mm);
  std::vector<char> processed(filtered->size(), 0);
  for (size_t i = 0; i < filtered->size(); ++i) {
    if (processed[i]) continue;
    std::vector<int> queue = grow_smooth_region(*filtered, *tree, i, tol, eps, processed);
    if (queue.size() < min_pts) continue;
    std::sort(queue.begin(), queue.end());
    regions.push_back(region_of(*filtered, queue));
  }
  return regions;
}

}  // namespace pb::global
