#include "eval/symmetry.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "core/error.h"

namespace pb {

int continuous_symmetry_steps(double max_sym_disc_step) {
  if (!(max_sym_disc_step > 0.0) || !std::isfinite(max_sym_disc_step)) {
    throw std::invalid_argument("max_sym_disc_step must be a positive number, got " +
                                std::to_string(max_sym_disc_step));
  }
  return static_cast<int>(std::ceil(M_PI / max_sym_disc_step));
}

std::vector<Pose> symmetry_transformations(const std::vector<Mat4>& discrete,
                                           const std::vector<ContinuousSymmetry>& continuous,
                                           const SymmetryOptions& opt) {
  const int steps = continuous_symmetry_steps(opt.max_sym_disc_step);

  std::vector<Pose> disc;
  disc.push_back(Pose::identity());
  for (size_t i = 0; i < discrete.size(); ++i) {
    if (!discrete[i].allFinite()) {
      throw InputError("", "symmetries_discrete[" + std::to_string(i) + "]",
                       "the 4x4 matrix has a non-finite element");
    }
    disc.push_back(Pose::from_matrix(discrete[i]));
  }

  std::vector<Pose> cont;
  const double step = 2.0 * M_PI / steps;
  for (size_t k = 0; k < continuous.size(); ++k) {
    const Vec3& axis = continuous[k].axis;
    const Vec3& offset = continuous[k].offset;
    if (!axis.allFinite() || axis.norm() == 0.0 || !offset.allFinite()) {
      throw InputError("", "symmetries_continuous[" + std::to_string(k) + "].axis",
                       "the axis must be a finite non-zero vector and the offset finite");
    }
    const Vec3 a = axis.normalized();
    for (int i = 0; i < steps; ++i) {
      Pose c;
      c.R = Eigen::AngleAxisd(i * step, a).toRotationMatrix();
      c.t = -c.R * offset + offset;
      cont.push_back(c);
    }
  }

  std::vector<Pose> out;
  out.reserve(disc.size() * std::max<size_t>(1, cont.size()));
  for (const Pose& d : disc) {
    if (cont.empty()) {
      out.push_back(d);
      continue;
    }
    for (const Pose& c : cont) out.push_back(c * d);  // R = Rc Rd, t = Rc td + tc
  }
  return out;
}

std::vector<Pose> symmetry_transformations(const ModelInfo& info, const SymmetryOptions& opt) {
  return symmetry_transformations(info.symmetries_discrete, info.symmetries_continuous, opt);
}

}  // namespace pb
