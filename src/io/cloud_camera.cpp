// From a point cloud to what the pipeline takes: intrinsics (fitted or
// virtual) and a depth image (see io/cloud.h).
#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.h"
#include "io/cloud.h"
#include "io/validate.h"

namespace pb {

namespace {

// Least squares of y = a x + b; false when x does not vary.
bool fit_line(const std::vector<double>& x, const std::vector<double>& y, double* a, double* b) {
  const double n = static_cast<double>(x.size());
  double mx = 0, my = 0;
  for (size_t i = 0; i < x.size(); ++i) mx += x[i], my += y[i];
  mx /= n, my /= n;
  double sxx = 0, sxy = 0;
  for (size_t i = 0; i < x.size(); ++i) sxx += (x[i] - mx) * (x[i] - mx), sxy += (x[i] - mx) * (y[i] - my);
  if (!(sxx > 1e-18 * n)) return false;
  *a = sxy / sxx;
  *b = my - *a * mx;
  return true;
}

double percentile95(std::vector<double> v) {
  const size_t k = std::min(v.size() - 1, static_cast<size_t>(0.95 * static_cast<double>(v.size())));
  std::nth_element(v.begin(), v.begin() + static_cast<long>(k), v.end());
  return v[k];
}

}  // namespace

Intrinsics fit_intrinsics(const PointCloudFile& c, const std::string& path) {
  if (!c.organized()) throw InputError(path, "intrinsics", "an unorganized cloud has no pixel grid to fit intrinsics to");
  std::vector<double> a, u, b, v;
  for (int row = 0; row < c.height; ++row)
    for (int col = 0; col < c.width; ++col) {
      const Vec3f& p = c.points[static_cast<size_t>(row) * c.width + col];
      if (!p.allFinite() || !(p.z() > 0)) continue;
      a.push_back(static_cast<double>(p.x()) / p.z());
      b.push_back(static_cast<double>(p.y()) / p.z());
      u.push_back(col);
      v.push_back(row);
    }
  if (a.size() < 100)
    throw InputError(path, "intrinsics", "only " + std::to_string(a.size()) + " points in front of the camera: give the intrinsics");
  Intrinsics K;
  K.width = c.width;
  K.height = c.height;
  if (!fit_line(a, u, &K.fx, &K.cx) || !fit_line(b, v, &K.fy, &K.cy))
    throw InputError(path, "intrinsics", "the points do not spread over the image: give the intrinsics");
  std::vector<double> res;
  res.reserve(a.size());
  for (size_t i = 0; i < a.size(); ++i)
    res.push_back(std::max(std::abs(K.fx * a[i] + K.cx - u[i]), std::abs(K.fy * b[i] + K.cy - v[i])));
  const double r95 = percentile95(res);
  if (!(r95 <= 0.5)) {
    throw InputError(path, "intrinsics",
                     "the points are not a pinhole back-projection of the pixel grid (95% of them within " +
                         std::to_string(r95) + " px of the best fit, 0.5 needed): give the intrinsics");
  }
  validate_intrinsics(K, path, "intrinsics (fitted)");
  return K;
}

DepthImage organized_depth(const PointCloudFile& c) {
  DepthImage d(c.width, c.height);
  for (size_t i = 0; i < c.points.size() && i < d.z.size(); ++i) {
    const Vec3f& p = c.points[i];
    if (p.allFinite() && p.z() > 0) d.z[i] = p.z();
  }
  return d;
}

DepthImage project_cloud(const PointCloudFile& c, const Intrinsics& K) {
  DepthImage d(K.width, K.height);
  for (const Vec3f& p : c.points) {
    if (!p.allFinite() || !(p.z() > 0)) continue;
    const double u = std::round(K.fx * p.x() / p.z() + K.cx), v = std::round(K.fy * p.y() / p.z() + K.cy);
    if (!(u >= 0 && v >= 0 && u < K.width && v < K.height)) continue;
    float& z = d.at(static_cast<int>(u), static_cast<int>(v));
    if (z == 0 || p.z() < z) z = p.z();
  }
  return d;
}

Intrinsics virtual_camera(const PointCloudFile& c, const std::string& path, int width, int height) {
  double a0 = std::numeric_limits<double>::infinity(), a1 = -a0, b0 = a0, b1 = -a0;
  for (const Vec3f& p : c.points) {
    if (!p.allFinite() || !(p.z() > 0)) continue;
    const double a = static_cast<double>(p.x()) / p.z(), b = static_cast<double>(p.y()) / p.z();
    a0 = std::min(a0, a), a1 = std::max(a1, a), b0 = std::min(b0, b), b1 = std::max(b1, b);
  }
  if (!(a1 >= a0)) throw InputError(path, "intrinsics", "no point lies in front of the camera (z > 0)");
  const double margin = 1.04;  // 2% on each side
  const double fa = a1 > a0 ? (width - 1) / ((a1 - a0) * margin) : 1e9;
  const double fb = b1 > b0 ? (height - 1) / ((b1 - b0) * margin) : 1e9;
  Intrinsics K;
  K.width = width;
  K.height = height;
  K.fx = K.fy = std::min({fa, fb, 1e5});
  K.cx = 0.5 * (width - 1) - K.fx * 0.5 * (a0 + a1);
  K.cy = 0.5 * (height - 1) - K.fy * 0.5 * (b0 + b1);
  return K;
}

}  // namespace pb
