// Organized PCD export (for pcl_viewer, CloudCompare). PCL stays inside
// pcd.cpp: this header is plain posebench types.
#pragma once

#include <string>

#include "core/types.h"

namespace pb {

// PCD data encodings PCL writes (and io/cloud.h reads).
enum class PcdEncoding { binary, ascii, binary_compressed };

// Writes an organized cloud as a PCD (binary unless `encoding` says otherwise): WIDTH x HEIGHT points (x y z,
// float, mm, camera frame), NaN where a pixel has no depth, so the image
// structure survives. `scale` multiplies the coordinates (1 = mm, 0.001 =
// metres for viewers that expect metres). Written to PATH.tmp and renamed.
// InputError(path, "pcd", ...) if it cannot be written.
void write_organized_pcd(const std::string& path, const OrganizedCloud& cloud, double scale = 1.0,
                         PcdEncoding encoding = PcdEncoding::binary);

// Convenience: the organized cloud of a depth image through its intrinsics.
void write_organized_pcd(const std::string& path, const DepthImage& depth, const Intrinsics& K,
                         double scale = 1.0, PcdEncoding encoding = PcdEncoding::binary);

}  // namespace pb
