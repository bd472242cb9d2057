// Scenes given as point clouds: PCD files (PCL's format: ascii, binary and
// binary_compressed data, organized or not) and PLY clouds (the vertices of
// a PLY, faces ignored), read without PCL, and turned into what the
// recognition pipeline takes, a depth image with its intrinsics.
//
// Frames and units: the points are in the camera frame, OpenCV convention
// (x right, y down, z forward: what PCL's OpenNI grabbers write); a PCD's
// VIEWPOINT (sensor pose) other than the identity is undone, so points come
// back in the sensor's frame. Files in metres (PCL's convention) or
// millimetres (posebench's) are told apart by CloudUnits.
#pragma once

#include <string>
#include <vector>

#include "core/types.h"

namespace pb {

enum class CloudUnits {
  automatic,    // metres when the median depth of the finite points is below 20 (file units), else mm
  millimetres,
  metres,
};
// "auto", "mm" or "m"; InputError(field) otherwise.
CloudUnits parse_cloud_units(const std::string& text, const std::string& field);

struct PointCloudFile {
  int width = 0;               // organized: points per row; unorganized: the point count
  int height = 1;              // organized when > 1
  std::vector<Vec3f> points;   // mm, camera frame, row-major; NaN = no point (organized holes)
  bool metres = false;         // the file was read as metres (and scaled to mm)
  bool organized() const { return height > 1; }
};

// Reads a .pcd or .ply (by extension, case-insensitive). Fields x, y, z are
// required (float or double; PCD also integer types); other fields are
// skipped. InputError(path, field, ...) for anything malformed: header
// keywords and counts, data shorter or longer than declared, a corrupt
// compressed block, no finite point. Points with an infinite coordinate
// count as no point.
PointCloudFile read_cloud(const std::string& path, CloudUnits units = CloudUnits::automatic);

// The same from the bytes of a file (`path` names it in errors; its
// extension picks the format).
PointCloudFile parse_cloud(const std::string& path, const std::string& bytes, CloudUnits units);

// The pinhole intrinsics of an organized cloud, fitted to its points: for
// every finite point at pixel (u, v), u = fx x / z + cx and v = fy y / z + cy
// (least squares). InputError(path, "intrinsics") when fewer than 100 points
// have z > 0, when the fit is degenerate, or when points are off the fitted
// pinhole by more than 0.5 pixel at the 95th percentile (the cloud is not a
// depth image's back-projection: give the intrinsics).
Intrinsics fit_intrinsics(const PointCloudFile& cloud, const std::string& path);

// The depth image of an organized cloud (its z per pixel, 0 where no point
// or z <= 0).
DepthImage organized_depth(const PointCloudFile& cloud);

// Any cloud projected through K (z-buffer: the nearest point per pixel);
// points behind the camera or outside the image are dropped.
DepthImage project_cloud(const PointCloudFile& cloud, const Intrinsics& K);

// A virtual camera for an unorganized cloud without intrinsics: width x
// height pixels, square, centred on the points' angular extent (x/z, y/z of
// points with z > 0) with a 2% margin. InputError(path, "intrinsics") when
// no point lies in front of the camera.
Intrinsics virtual_camera(const PointCloudFile& cloud, const std::string& path, int width = 640, int height = 480);

}  // namespace pb
