#include "io_pcl/pcd.h"

#include <pcl/io/pcd_io.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cstdio>
#include <limits>

#include "core/error.h"

namespace pb {

void write_organized_pcd(const std::string& path, const OrganizedCloud& cloud, double scale, PcdEncoding encoding) {
  if (cloud.width <= 0 || cloud.height <= 0 ||
      cloud.points.size() != static_cast<size_t>(cloud.width) * cloud.height)
    throw InputError(path, "pcd", "organized cloud size does not match width x height");
  if (!(scale > 0)) throw InputError(path, "pcd", "scale must be positive");
  pcl::PointCloud<pcl::PointXYZ> pc;
  pc.width = static_cast<uint32_t>(cloud.width);
  pc.height = static_cast<uint32_t>(cloud.height);
  pc.is_dense = false;
  pc.points.resize(cloud.points.size());
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float k = static_cast<float>(scale);
  for (size_t i = 0; i < cloud.points.size(); ++i) {
    const Vec3f& p = cloud.points[i];
    if (p.allFinite())
      pc.points[i] = pcl::PointXYZ(p.x() * k, p.y() * k, p.z() * k);
    else
      pc.points[i] = pcl::PointXYZ(nan, nan, nan);
  }
  const std::string tmp = path + ".tmp";
  int rc = -1;
  try {
    rc = encoding == PcdEncoding::ascii    ? pcl::io::savePCDFileASCII(tmp, pc)
         : encoding == PcdEncoding::binary ? pcl::io::savePCDFileBinary(tmp, pc)
                                           : pcl::io::savePCDFileBinaryCompressed(tmp, pc);
  } catch (const std::exception& e) {
    std::remove(tmp.c_str());
    throw InputError(path, "pcd", std::string("cannot write PCD: ") + e.what());
  }
  if (rc != 0) {
    std::remove(tmp.c_str());
    throw InputError(path, "pcd", "cannot write PCD (error " + std::to_string(rc) + ")");
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    throw InputError(path, "pcd", "cannot move the PCD file into place");
  }
}

void write_organized_pcd(const std::string& path, const DepthImage& depth, const Intrinsics& K, double scale,
                         PcdEncoding encoding) {
  write_organized_pcd(path, OrganizedCloud::from_depth(depth, K), scale, encoding);
}

}  // namespace pb
