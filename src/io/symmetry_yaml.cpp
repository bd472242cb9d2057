#include "io/symmetry_yaml.h"

#include <cmath>

namespace pb {

namespace {

Mat4 read_matrix4(const YamlNode& n) {
  std::vector<double> v;
  if (n.is_sequence() && n.size() == 4 && n.at(0).is_sequence()) {
    for (size_t r = 0; r < 4; ++r) {
      const auto row = n.at(r).as<std::vector<double>>();
      if (row.size() != 4) n.at(r).fail("expected a row of 4 numbers");
      v.insert(v.end(), row.begin(), row.end());
    }
  } else {
    if (!n.is_sequence()) n.fail("expected a 4x4 matrix: 16 numbers row-major or 4 rows of 4");
    v = n.as<std::vector<double>>();
    if (v.size() != 16) n.fail("expected a 4x4 matrix: 16 numbers row-major or 4 rows of 4");
  }
  Mat4 T;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) T(r, c) = v[4 * r + c];
  const Mat3 R = T.block<3, 3>(0, 0);
  if ((R * R.transpose() - Mat3::Identity()).norm() > 1e-6 || std::abs(R.determinant() - 1) > 1e-6)
    n.fail("the 3x3 part is not a rotation (orthonormal, determinant +1)");
  if (T.row(3) != Eigen::RowVector4d(0, 0, 0, 1)) n.fail("the last row must be 0 0 0 1");
  return T;
}

Vec3 read_vec3(const YamlNode& n) {
  if (!n.is_sequence()) n.fail("expected a list of 3 numbers");
  const auto v = n.as<std::vector<double>>();
  if (v.size() != 3) n.fail("expected a list of 3 numbers");
  return Vec3(v[0], v[1], v[2]);
}

}  // namespace

void read_symmetries(const YamlNode& e, std::vector<Mat4>& discrete, std::vector<ContinuousSymmetry>& continuous) {
  if (e.has("symmetries_discrete")) {
    const YamlNode l = e["symmetries_discrete"];
    if (!l.is_sequence()) l.fail("expected a list of 4x4 matrices");
    for (size_t i = 0; i < l.size(); ++i) discrete.push_back(read_matrix4(l.at(i)));
  }
  if (e.has("symmetries_continuous")) {
    const YamlNode l = e["symmetries_continuous"];
    if (!l.is_sequence()) l.fail("expected a list of {axis, offset}");
    for (size_t i = 0; i < l.size(); ++i) {
      const YamlNode c = l.at(i);
      c.check_keys({"axis", "offset"});
      ContinuousSymmetry cs;
      cs.axis = read_vec3(c["axis"]);
      if (!(cs.axis.norm() > 0)) c["axis"].fail("axis must not be zero");
      cs.axis.normalize();
      if (c.has("offset")) cs.offset = read_vec3(c["offset"]);
      continuous.push_back(cs);
    }
  }
}

}  // namespace pb
