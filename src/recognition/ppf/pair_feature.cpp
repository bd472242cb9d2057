// PPF's pair feature, PCL's bit for bit (ppf/internal.h pair_feature), and
// PCL's own for the tests.
#include <pcl/features/pfh_tools.h>

#include <algorithm>
#include <cmath>

#include "recognition/ppf/internal.h"

namespace pb::ppf {

namespace {

// Eigen's Vector4f dot product with a zero fourth lane, in its SSE
// reduction order: (x + z) + (y + 0). The + 0 keeps the sign of a zero sum
// as Eigen's does (atan2 tells -0 from +0).
inline float dot4(const Vec3f& a, const Vec3f& b) {
  return (a.x() * b.x() + a.z() * b.z()) + (a.y() * b.y() + 0.0f);
}

// PCL's choice of source point: acos(|c1|) > acos(|c2|). acos is
// decreasing on [0, 1] with slope at most -1 and rounds to within an ulp
// (at most 1.2e-7 below pi / 2), so cosines 1e-6 apart decide it alone;
// closer ones, values above 1 (acos gives NaN) and NaN take PCL's test.
inline bool second_is_source(float c1, float c2) {
  const float a1 = std::fabs(c1), a2 = std::fabs(c2);
  constexpr float kSure = 1e-6f;
  if (a2 <= 1.0f && a1 < a2 - kSure) return true;
  if (a1 <= 1.0f && a2 < a1 - kSure) return false;
  return std::acos(a1) > std::acos(a2);
}

}  // namespace

bool pair_feature(const Vec3f& p1, const Vec3f& n1, const Vec3f& p2, const Vec3f& n2, float f[4]) {
  float y = 0, x = 0;
  if (!pair_feature_parts(p1, n1, p2, n2, f, &y, &x)) return false;
  f[0] = std::atan2(y, x);
  return true;
}

bool pair_feature_parts(const Vec3f& p1, const Vec3f& n1, const Vec3f& p2, const Vec3f& n2, float f[4], float* y,
                        float* x) {
  Vec3f d = p2 - p1;
  f[3] = std::sqrt(dot4(d, d));
  if (f[3] == 0.0f) {
    f[0] = f[1] = f[2] = 0.0f;
    return false;
  }
  const float c1 = dot4(n1, d) / f[3], c2 = dot4(n2, d) / f[3];
  Vec3f u = n1, target = n2;
  f[2] = c1;
  if (second_is_source(c1, c2)) {
    u = n2;
    target = n1;
    d = -d;
    f[2] = -c2;
  }
  Vec3f v = d.cross(u);
  const float vn = std::sqrt(dot4(v, v));
  if (vn == 0.0f) {
    f[0] = f[1] = f[2] = f[3] = 0.0f;
    return false;
  }
  v /= vn;
  const Vec3f w = u.cross(v);
  f[1] = dot4(v, target);
  *y = dot4(w, target);
  *x = dot4(u, target);
  return true;
}

bool pcl_pair_feature(const Vec3f& p1, const Vec3f& n1, const Vec3f& p2, const Vec3f& n2, float f[4]) {
  auto v4 = [](const Vec3f& v) { return Eigen::Vector4f(v.x(), v.y(), v.z(), 0.f); };
  return pcl::computePairFeatures(v4(p1), v4(n1), v4(p2), v4(n2), f[0], f[1], f[2], f[3]);
}

}  // namespace pb::ppf
