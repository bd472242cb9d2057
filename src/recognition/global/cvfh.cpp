// CVFH signatures through pcl::CVFHEstimation.
#include <pcl/features/cvfh.h>

#include <cmath>

#include "recognition/global/internal.h"
#include "recognition/global/pcl_cvfh.h"

namespace pb::global {

std::vector<Signature> cvfh_signatures(const PointSet& cloud, const GlobalSettings& s) {
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

}  // namespace pb::global
