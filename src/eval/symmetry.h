// The symmetry set of a model, as the BOP toolkit defines it
// (bop_toolkit_lib/misc.py, get_symmetry_transformations; restated in
// ../shared/reference/BOP.md). Every symmetry S is a Pose of the model frame
// onto itself (x -> S.R x + S.t): the model at pose T_cam_model * S looks
// exactly like the model at T_cam_model.
#pragma once

#include <vector>

#include "core/types.h"
#include "io/bop.h"

namespace pb {

struct SymmetryOptions {
  // BOP's max_sym_disc_step: the largest fraction of the object diameter that
  // the vertex furthest from a continuous symmetry axis travels between two
  // consecutive discretized rotations. A continuous symmetry becomes
  // n = ceil(pi / max_sym_disc_step) rotations by i * 2 pi / n, i = 0..n-1
  // (315 for the BOP default 0.01). Must be > 0.
  double max_sym_disc_step = 0.01;
};

// The symmetry set, in the toolkit's order: for each discrete symmetry D
// (the identity first, then `discrete` in order) and, if there are continuous
// symmetries, for each discretized rotation C of each continuous symmetry
// (concatenated, not combined with each other), the composition C * D:
// R = C.R * D.R, t = C.R * D.t + C.t, where C.t = -C.R * offset + offset.
// Without continuous symmetries the set is {identity} + discrete.
// Element 0 is always the identity.
// Throws InputError (field "symmetries_continuous[i].axis") for a zero or
// non-finite axis and (field "symmetries_discrete[i]") for a non-finite
// matrix, and std::invalid_argument for max_sym_disc_step <= 0.
std::vector<Pose> symmetry_transformations(const std::vector<Mat4>& discrete,
                                           const std::vector<ContinuousSymmetry>& continuous,
                                           const SymmetryOptions& opt = {});

// The same from a models_info entry (its symmetries_discrete and
// symmetries_continuous).
std::vector<Pose> symmetry_transformations(const ModelInfo& info, const SymmetryOptions& opt = {});

// Number of discretized rotations per continuous symmetry:
// ceil(pi / max_sym_disc_step).
int continuous_symmetry_steps(double max_sym_disc_step);

}  // namespace pb
