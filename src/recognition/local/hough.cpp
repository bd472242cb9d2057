// Correspondence grouping of the local pipeline: 3D Hough voting
// (pcl::Hough3DGrouping, Tombari & Di Stefano 2010) over the BOARD frames of
// board.cpp. Hough3DGrouping filters
// each cluster with PCL's RANSAC correspondence rejector (fixed seed 12345,
// single-threaded), so its output is deterministic.
#include <pcl/correspondence.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/recognition/cg/hough_3d.h>
#include <pcl/search/kdtree.h>

#include <algorithm>
#include <limits>
#include <set>

#include "recognition/local/internal.h"
#include "recognition/local/pcl_features.h"

namespace pb::local {

namespace {

pcl::PointCloud<pcl::ReferenceFrame>::Ptr to_rf(const std::vector<float>& lrf, size_t n) {
  pcl::PointCloud<pcl::ReferenceFrame>::Ptr rf(new pcl::PointCloud<pcl::ReferenceFrame>);
  rf->resize(n);
  for (size_t i = 0; i < n; ++i)
    for (int d = 0; d < 3; ++d) {
      (*rf)[i].x_axis[d] = lrf[i * kLrfDim + d];
      (*rf)[i].y_axis[d] = lrf[i * kLrfDim + 3 + d];
      (*rf)[i].z_axis[d] = lrf[i * kLrfDim + 6 + d];
    }
  return rf;
}

}  // namespace

std::vector<HoughCluster> hough_grouping(const std::vector<Vec3f>& model_kp,
                                         const std::vector<float>& model_lrf,
                                         const std::vector<Vec3f>& scene_kp,
                                         const std::vector<float>& scene_lrf,
                                         const std::vector<Match>& matches, const HoughParams& p) {
  std::vector<HoughCluster> out;
  if (matches.empty() || model_kp.empty() || scene_kp.empty()) return out;
  if (static_cast<double>(matches.size()) < p.min_votes) return out;

  // PCL's RANSAC stage (SampleConsensusModelRegistration) keys
  // correspondences by model index and rejects index lists longer than the
  // model cloud, so a model keypoint matched by several scene keypoints would
  // break it. Give every match its own copy of the model keypoint (and LRF):
  // model indices become unique. The Hough reference point (the centroid of
  // the copies) is arbitrary anyway: true matches all vote for the same point.
  std::vector<Vec3f> mk;
  std::vector<float> ml;
  pcl::CorrespondencesPtr corrs(new pcl::Correspondences);
  mk.reserve(matches.size());
  ml.reserve(matches.size() * kLrfDim);
  corrs->reserve(matches.size());
  for (size_t i = 0; i < matches.size(); ++i) {
    const Match& m = matches[i];
    mk.push_back(model_kp[m.model]);
    ml.insert(ml.end(), model_lrf.begin() + static_cast<long>(m.model) * kLrfDim,
              model_lrf.begin() + static_cast<long>(m.model + 1) * kLrfDim);
    corrs->emplace_back(static_cast<int>(i), m.scene, m.distance);
  }

  pcl::Hough3DGrouping<pcl::PointXYZ, pcl::PointXYZ, pcl::ReferenceFrame, pcl::ReferenceFrame> hough;
  hough.setHoughBinSize(p.bin_mm);
  hough.setHoughThreshold(p.min_votes);
  hough.setUseInterpolation(p.interpolation);
  hough.setUseDistanceWeight(false);
  hough.setInputCloud(pcl_adapter::xyz(mk));
  hough.setInputRf(to_rf(ml, mk.size()));
  hough.setSceneCloud(pcl_adapter::xyz(scene_kp));
  hough.setSceneRf(to_rf(scene_lrf, scene_kp.size()));
  hough.setModelSceneCorrespondences(corrs);

  std::vector<Eigen::Matrix4f, Eigen::aligned_allocator<Eigen::Matrix4f>> transforms;
  std::vector<pcl::Correspondences> clustered;
  hough.recognize(transforms, clustered);

  for (const pcl::Correspondences& c : clustered) {
    HoughCluster hc;
    std::set<std::pair<int, int>> seen;
    for (const pcl::Correspondence& k : c) {
      const Match& m = matches[static_cast<size_t>(k.index_query)];
      if (seen.emplace(m.model, m.scene).second) hc.matches.push_back(m);
    }
    std::sort(hc.matches.begin(), hc.matches.end(), [](const Match& a, const Match& b) {
      return a.model < b.model || (a.model == b.model && a.scene < b.scene);
    });
    out.push_back(std::move(hc));
  }
  return out;
}

}  // namespace pb::local
