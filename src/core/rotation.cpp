#include "core/rotation.h"

#include <algorithm>
#include <cmath>

namespace pb {

Eigen::Quaterniond to_quaternion(const Mat3& R) { return Eigen::Quaterniond(R).normalized(); }

double rotation_angle_deg(const Mat3& Ra, const Mat3& Rb) {
  const double c = std::clamp(((Ra.transpose() * Rb).trace() - 1.0) / 2.0, -1.0, 1.0);
  return std::acos(c) * 180.0 / M_PI;
}

Mat3 axis_angle(const Vec3& axis, double angle_rad) {
  return Eigen::AngleAxisd(angle_rad, axis.normalized()).toRotationMatrix();
}

Mat3 random_rotation(Rng& rng) {
  // Shoemake's uniform random unit quaternion.
  const double u1 = rng.uniform(), u2 = rng.uniform(), u3 = rng.uniform();
  const double a = std::sqrt(1 - u1), b = std::sqrt(u1);
  Eigen::Quaterniond q(b * std::cos(2 * M_PI * u3), a * std::sin(2 * M_PI * u2),
                       a * std::cos(2 * M_PI * u2), b * std::sin(2 * M_PI * u3));
  return q.normalized().toRotationMatrix();
}

Pose look_at(const Vec3& eye, const Vec3& target, const Vec3& up) {
  const Vec3 z = (target - eye).normalized();  // forward
  Vec3 x = (-up).cross(z);                     // right = y x z with y (down) ~ -up
  if (x.norm() < 1e-9) x = z.unitOrthogonal();
  x.normalize();
  const Vec3 y = z.cross(x);
  Pose T_world_cam;
  T_world_cam.R.col(0) = x;
  T_world_cam.R.col(1) = y;
  T_world_cam.R.col(2) = z;
  T_world_cam.t = eye;
  return T_world_cam;
}

}  // namespace pb
