// Verification (thesis 3.1): inliers are model points whose nearest scene
// point lies within a threshold. PointIndex wraps pcl::KdTreeFLANN.
#include "recognition/pcl_adapter.h"
#include "recognition/verify/verify.h"

#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cmath>
#include <limits>
#include <stdexcept>

namespace pb {

struct PointIndex::Impl {
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud{new pcl::PointCloud<pcl::PointXYZ>};
  pcl::KdTreeFLANN<pcl::PointXYZ> tree{true};  // sorted radius results
};

PointIndex::PointIndex(const std::vector<Vec3f>& points) : impl_(new Impl) {
  for (const auto& p : points)
    if (!p.allFinite()) throw std::invalid_argument("PointIndex: non-finite point");  // callers pass finite clouds
  impl_->cloud = pcl_adapter::xyz(points);
  if (!impl_->cloud->empty()) impl_->tree.setInputCloud(impl_->cloud);
}

PointIndex::~PointIndex() = default;

size_t PointIndex::size() const { return impl_->cloud->size(); }

int PointIndex::nearest(const Vec3f& q, float* sq_dist) const {
  if (impl_->cloud->empty() || !q.allFinite()) {
    if (sq_dist) *sq_dist = std::numeric_limits<float>::infinity();
    return -1;
  }
  pcl::Indices idx(1);
  std::vector<float> d(1);
  if (impl_->tree.nearestKSearch(pcl::PointXYZ(q.x(), q.y(), q.z()), 1, idx, d) < 1) {
    if (sq_dist) *sq_dist = std::numeric_limits<float>::infinity();
    return -1;
  }
  if (sq_dist) *sq_dist = d[0];
  return idx[0];
}

std::vector<int> PointIndex::radius(const Vec3f& q, float r) const {
  std::vector<int> out;
  if (impl_->cloud->empty() || !q.allFinite() || !(r > 0)) return out;
  pcl::Indices idx;
  std::vector<float> d;
  impl_->tree.radiusSearch(pcl::PointXYZ(q.x(), q.y(), q.z()), r, idx, d);
  out.assign(idx.begin(), idx.end());
  return out;
}

int count_inliers(const std::vector<Vec3f>& model_points, const Pose& T_cam_model, const PointIndex& scene,
                  double threshold_mm) {
  if (scene.size() == 0) return 0;
  const Eigen::Matrix3d R = T_cam_model.R;
  const Vec3 t = T_cam_model.t;
  const float thr2 = static_cast<float>(threshold_mm * threshold_mm);
  int n = 0;
  for (const auto& p : model_points) {
    const Vec3f q = (R * p.cast<double>() + t).cast<float>();
    float d2;
    if (scene.nearest(q, &d2) >= 0 && d2 <= thr2) ++n;
  }
  return n;
}

}  // namespace pb
