// PCL's ESF, as the reference for our own (global_esf.cpp). Not used by the
// pipeline: pcl::ESFEstimation calls srand(time(nullptr)) and rand().
#include <pcl/features/esf.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include "recognition/global/internal.h"
#include "pcl_reference.h"

namespace pb::global {

std::vector<float> pcl_esf(const std::vector<Vec3f>& points) {
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  for (const auto& p : points) {
    if (!p.allFinite()) continue;
    pcl::PointXYZ q;
    q.getVector3fMap() = p;
    cloud->push_back(q);
  }
  if (cloud->size() < 3) return std::vector<float>(640, 0.f);
  pcl::ESFEstimation<pcl::PointXYZ, pcl::ESFSignature640> esf;
  esf.setInputCloud(cloud);
  pcl::PointCloud<pcl::ESFSignature640> out;
  esf.compute(out);
  if (out.size() != 1) return std::vector<float>(640, 0.f);
  return std::vector<float>(out[0].histogram, out[0].histogram + 640);
}

}  // namespace pb::global
