// Rotation helpers: quaternions, angles, random rotations.
#pragma once

#include "core/random.h"
#include "core/types.h"

namespace pb {

Eigen::Quaterniond to_quaternion(const Mat3& R);
// Angle of the rotation R_a^T R_b in degrees.
double rotation_angle_deg(const Mat3& Ra, const Mat3& Rb);
// Rotation about a unit axis by an angle in radians.
Mat3 axis_angle(const Vec3& axis, double angle_rad);
// Uniformly distributed random rotation.
Mat3 random_rotation(Rng& rng);
// Camera pose looking from `eye` at `target`, with the image's "up" (-y of the
// camera) as close as possible to `up` (world). Returns T_world_cam.
Pose look_at(const Vec3& eye, const Vec3& target, const Vec3& up);

}  // namespace pb
