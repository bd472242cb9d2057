// Core value types shared by every stage: poses, intrinsics, depth images.
// Units: millimetres. Camera: OpenCV convention (x right, y down, z forward),
// pixel (u, v) has its centre at integer coordinates, as in BOP.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

namespace pb {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Mat4 = Eigen::Matrix4d;
using Vec3f = Eigen::Vector3f;

// A rigid transform named by its frames: Pose T_a_b maps points of frame b
// into frame a (x_a = R * x_b + t). T_cam_model maps model points into the
// camera frame; its R and t are BOP's cam_R_m2c and cam_t_m2c (mm).
struct Pose {
  Mat3 R = Mat3::Identity();  // rotation, row-major when serialized
  Vec3 t = Vec3::Zero();      // translation in millimetres

  static Pose identity() { return {}; }
  static Pose from_matrix(const Mat4& T);
  Mat4 matrix() const;
  Pose inverse() const;
  Pose operator*(const Pose& o) const;  // composition: (this * o)(x) = this(o(x))
  Vec3 operator*(const Vec3& x) const { return R * x + t; }
};

// Pinhole intrinsics of an image of width x height pixels.
struct Intrinsics {
  int width = 0;
  int height = 0;
  double fx = 0, fy = 0;  // focal lengths in pixels
  double cx = 0, cy = 0;  // principal point in pixels (pixel centres at integers)

  Mat3 K() const;
  static Intrinsics from_K(const Mat3& K, int width, int height);
  // Focal lengths from a horizontal and a vertical field of view (deg);
  // the principal point at the image centre ((w-1)/2, (h-1)/2).
  static Intrinsics from_fov(int width, int height, double hfov_deg, double vfov_deg);
  // Projects a camera-frame point (mm) to pixel coordinates.
  Eigen::Vector2d project(const Vec3& p_cam) const;
  // Back-projects pixel (u, v) with depth z (mm, along the optical axis).
  Vec3 backproject(double u, double v, double z) const;
};

// A depth image: z along the optical axis in millimetres, row-major,
// index v * width + u. 0 means no measurement. NaN never appears in a valid
// DepthImage: readers convert or reject it.
struct DepthImage {
  int width = 0;
  int height = 0;
  std::vector<float> z;

  DepthImage() = default;
  DepthImage(int w, int h) : width(w), height(h), z(static_cast<size_t>(w) * h, 0.f) {}
  float& at(int u, int v) { return z[static_cast<size_t>(v) * width + u]; }
  float at(int u, int v) const { return z[static_cast<size_t>(v) * width + u]; }
  size_t valid_count() const;
  // Whether it is an image of K's size with one depth per pixel.
  bool fits(const Intrinsics& K) const {
    return width == K.width && height == K.height && z.size() == static_cast<size_t>(width) * static_cast<size_t>(height);
  }
};

// A triangle mesh in model coordinates (mm after scaling).
struct Mesh {
  std::vector<Vec3f> vertices;
  std::vector<Eigen::Vector3i> faces;  // indices into vertices, counter-clockwise outward
  std::vector<Vec3f> vertex_normals;   // optional; empty when not computed

  bool empty() const { return vertices.empty() || faces.empty(); }
  Eigen::AlignedBox3f bounds() const;
  double diameter() const;  // largest distance between two vertices (BOP)
  void compute_vertex_normals();
  void transform(const Pose& T);  // applies T to every vertex (and normal)
  void append(const Mesh& other);
};

// An organized point cloud from a depth image: one point per pixel, NaN where
// there is no depth. Points in the camera frame, mm.
struct OrganizedCloud {
  int width = 0;
  int height = 0;
  std::vector<Vec3f> points;  // NaN for invalid pixels
  static OrganizedCloud from_depth(const DepthImage& depth, const Intrinsics& K);
  size_t valid_count() const;
};

}  // namespace pb
