#include "core/types.h"

#include <cmath>
#include <limits>
#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

#include "core/cpu.h"

namespace pb {

Pose Pose::from_matrix(const Mat4& T) {
  Pose p;
  p.R = T.block<3, 3>(0, 0);
  p.t = T.block<3, 1>(0, 3);
  return p;
}

Mat4 Pose::matrix() const {
  Mat4 T = Mat4::Identity();
  T.block<3, 3>(0, 0) = R;
  T.block<3, 1>(0, 3) = t;
  return T;
}

Pose Pose::inverse() const {
  Pose p;
  p.R = R.transpose();
  p.t = -(p.R * t);
  return p;
}

Pose Pose::operator*(const Pose& o) const {
  Pose p;
  p.R = R * o.R;
  p.t = R * o.t + t;
  return p;
}

Mat3 Intrinsics::K() const {
  Mat3 K = Mat3::Identity();
  K(0, 0) = fx;
  K(1, 1) = fy;
  K(0, 2) = cx;
  K(1, 2) = cy;
  return K;
}

Intrinsics Intrinsics::from_K(const Mat3& K, int width, int height) {
  Intrinsics in;
  in.width = width;
  in.height = height;
  in.fx = K(0, 0);
  in.fy = K(1, 1);
  in.cx = K(0, 2);
  in.cy = K(1, 2);
  return in;
}

Intrinsics Intrinsics::from_fov(int width, int height, double hfov_deg, double vfov_deg) {
  Intrinsics in;
  in.width = width;
  in.height = height;
  const double d2r = M_PI / 180.0;
  // The image spans width pixels edge to edge: fov covers width * pixel size.
  in.fx = 0.5 * width / std::tan(0.5 * hfov_deg * d2r);
  in.fy = 0.5 * height / std::tan(0.5 * vfov_deg * d2r);
  in.cx = 0.5 * (width - 1);
  in.cy = 0.5 * (height - 1);
  return in;
}

Eigen::Vector2d Intrinsics::project(const Vec3& p) const {
  return {fx * p.x() / p.z() + cx, fy * p.y() / p.z() + cy};
}

Vec3 Intrinsics::backproject(double u, double v, double z) const {
  return {(u - cx) * z / fx, (v - cy) * z / fy, z};
}

size_t DepthImage::valid_count() const {
  size_t n = 0;
  for (float d : z) n += (d > 0.f && std::isfinite(d));
  return n;
}

Eigen::AlignedBox3f Mesh::bounds() const {
  Eigen::AlignedBox3f b;
  for (const auto& v : vertices) b.extend(v);
  return b;
}

double Mesh::diameter() const {
  // Exact O(n^2) over vertices; meshes here are small (< 50k vertices) and
  // this runs once per model. Candidates are pruned by the bounding box
  // diagonal bound.
  double best = 0.0;
  const size_t n = vertices.size();
  for (size_t i = 0; i < n; ++i)
    for (size_t j = i + 1; j < n; ++j)
      best = std::max(best, static_cast<double>((vertices[i] - vertices[j]).squaredNorm()));
  return std::sqrt(best);
}

void Mesh::compute_vertex_normals() {
  vertex_normals.assign(vertices.size(), Vec3f::Zero());
  for (const auto& f : faces) {
    const Vec3f n = (vertices[f[1]] - vertices[f[0]]).cross(vertices[f[2]] - vertices[f[0]]);
    for (int k = 0; k < 3; ++k) vertex_normals[f[k]] += n;  // area weighted
  }
  for (auto& n : vertex_normals) {
    const float l = n.norm();
    if (l > 0) n /= l;
  }
}

void Mesh::transform(const Pose& T) {
  const Eigen::Matrix3f R = T.R.cast<float>();
  const Vec3f t = T.t.cast<float>();
  for (auto& v : vertices) v = R * v + t;
  for (auto& n : vertex_normals) n = R * n;
}

void Mesh::append(const Mesh& o) {
  const int off = static_cast<int>(vertices.size());
  const bool normals = !vertex_normals.empty() || vertices.empty();
  vertices.insert(vertices.end(), o.vertices.begin(), o.vertices.end());
  for (auto f : o.faces) faces.push_back(f + Eigen::Vector3i(off, off, off));
  if (normals && o.vertex_normals.size() == o.vertices.size())
    vertex_normals.insert(vertex_normals.end(), o.vertex_normals.begin(), o.vertex_normals.end());
  else
    vertex_normals.clear();
}

namespace {

// Pixels [from, width) of row v of from_depth: pixel u's point
// K.backproject(u, v, z) in float, or NaN where z is not a measurement (0,
// negative, NaN or infinite); z and out index the row.
void backproject_row(const float* z, int from, int width, int v, const Intrinsics& K, Vec3f* out) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int u = from; u < width; ++u)
    out[u] = z[u] > 0.f && std::isfinite(z[u]) ? K.backproject(u, v, z[u]).cast<float>() : Vec3f(nan, nan, nan);
}

#if defined(__x86_64__) || defined(__i386__)
// The same row four pixels at a time: each lane does backproject's double
// operations in its order, (u - cx) * z / fx and (v - cy) * z / fy, each
// correctly rounded as the scalar ones, then the same rounding to float.
// The divisions are most of the cost, four to an instruction here.
__attribute__((target("avx2"))) void backproject_row_avx2(const float* z, int width, int v, const Intrinsics& K,
                                                          Vec3f* out) {
  const __m256d cx = _mm256_set1_pd(K.cx), fx = _mm256_set1_pd(K.fx), fy = _mm256_set1_pd(K.fy);
  const __m256d vy = _mm256_set1_pd(static_cast<double>(v) - K.cy);
  const __m128 zero = _mm_setzero_ps(), inf = _mm_set1_ps(std::numeric_limits<float>::infinity());
  const __m128 nan = _mm_set1_ps(std::numeric_limits<float>::quiet_NaN());
  int u = 0;
  for (; u + 4 <= width; u += 4) {
    const __m128 zf = _mm_loadu_ps(z + u);
    const __m128 ok = _mm_and_ps(_mm_cmpgt_ps(zf, zero), _mm_cmplt_ps(zf, inf));  // z > 0, finite
    const __m256d zd = _mm256_cvtps_pd(zf);
    const __m256d ud = _mm256_set_pd(u + 3, u + 2, u + 1, u);
    const __m128 x = _mm256_cvtpd_ps(_mm256_div_pd(_mm256_mul_pd(_mm256_sub_pd(ud, cx), zd), fx));
    const __m128 y = _mm256_cvtpd_ps(_mm256_div_pd(_mm256_mul_pd(vy, zd), fy));
    alignas(16) float xs[4], ys[4], zs[4];
    _mm_store_ps(xs, _mm_blendv_ps(nan, x, ok));
    _mm_store_ps(ys, _mm_blendv_ps(nan, y, ok));
    _mm_store_ps(zs, _mm_blendv_ps(nan, zf, ok));
    for (int k = 0; k < 4; ++k) out[u + k] = Vec3f(xs[k], ys[k], zs[k]);
  }
  backproject_row(z, u, width, v, K, out);
}
#endif

}  // namespace

OrganizedCloud OrganizedCloud::from_depth(const DepthImage& depth, const Intrinsics& K) {
  OrganizedCloud c;
  c.width = depth.width;
  c.height = depth.height;
  c.points.resize(static_cast<size_t>(c.width) * c.height);  // every one written
  const bool avx2 = cpu_has_avx2();
  for (int v = 0; v < depth.height; ++v) {
    const float* z = depth.z.data() + static_cast<size_t>(v) * depth.width;
    Vec3f* out = c.points.data() + static_cast<size_t>(v) * c.width;
#if defined(__x86_64__) || defined(__i386__)
    if (avx2) {
      backproject_row_avx2(z, depth.width, v, K, out);
      continue;
    }
#endif
    backproject_row(z, 0, depth.width, v, K, out);
  }
  return c;
}

size_t OrganizedCloud::valid_count() const {
  size_t n = 0;
  for (const auto& p : points) n += std::isfinite(p.z());
  return n;
}

}  // namespace pb
