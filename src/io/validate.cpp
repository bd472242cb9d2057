#include "io/validate.h"

#include <cmath>
#include <cstdio>

#include "core/error.h"

namespace pb {

namespace {

std::string g(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

}  // namespace

void validate_rotation(const Mat3& R, double tolerance, const std::string& file, const std::string& field) {
  if (!R.allFinite()) throw InputError(file, field, "not a rotation matrix: a value is not finite");
  const double det = R.determinant();
  const double ortho = (R.transpose() * R - Mat3::Identity()).cwiseAbs().maxCoeff();
  if (std::abs(det - 1) > tolerance || ortho > tolerance)
    throw InputError(file, field,
                     "not a rotation matrix: det " + g(det) + ", max |R^T R - I| " + g(ortho) +
                         " (each must be within " + g(tolerance) + " of a rotation's)");
}

void validate_intrinsics(const Intrinsics& K, const std::string& file, const std::string& field) {
  const std::string pre = field.empty() ? "" : field + ".";
  for (const auto& [name, v] : {std::pair<const char*, double>{"fx", K.fx}, {"fy", K.fy}, {"cx", K.cx}, {"cy", K.cy}})
    if (!std::isfinite(v)) throw InputError(file, pre + name, "not a finite number");
  if (!(K.fx > 0)) throw InputError(file, pre + "fx", "must be positive (is " + g(K.fx) + ")");
  if (!(K.fy > 0)) throw InputError(file, pre + "fy", "must be positive (is " + g(K.fy) + ")");
  // tan(85 deg) = 11.43: a field of view of 170 degrees needs f = size / 22.86.
  constexpr double kMinFocalPerPixel = 1.0 / (2.0 * 11.430052302761343);
  if (K.width > 0 && K.fx < kMinFocalPerPixel * K.width)
    throw InputError(file, pre + "fx",
                     g(K.fx) + " px gives a horizontal field of view over 170 degrees at width " +
                         std::to_string(K.width) + " (focal lengths are in pixels, not normalized)");
  if (K.height > 0 && K.fy < kMinFocalPerPixel * K.height)
    throw InputError(file, pre + "fy",
                     g(K.fy) + " px gives a vertical field of view over 170 degrees at height " +
                         std::to_string(K.height) + " (focal lengths are in pixels, not normalized)");
  if (K.width > 0 && (K.cx < -K.width || K.cx > 2.0 * K.width))
    throw InputError(file, pre + "cx",
                     g(K.cx) + " is far outside the image (width " + std::to_string(K.width) + ")");
  if (K.height > 0 && (K.cy < -K.height || K.cy > 2.0 * K.height))
    throw InputError(file, pre + "cy",
                     g(K.cy) + " is far outside the image (height " + std::to_string(K.height) + ")");
}

void validate_camera_matrix(const Mat3& K, int width, int height, const std::string& file, const std::string& field) {
  if (K(1, 0) != 0 || K(2, 0) != 0 || K(2, 1) != 0 || K(2, 2) != 1)
    throw InputError(file, field, "expected [fx, 0, cx, 0, fy, cy, 0, 0, 1]");
  if (K(0, 1) != 0) throw InputError(file, field, "skew (the second value) must be 0: the camera model has none");
  validate_intrinsics(Intrinsics::from_K(K, width, height), file, field);
}

}  // namespace pb
