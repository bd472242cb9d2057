// Private to the refine_*.cpp files: what refine_pose and the methods
// share beyond the public Refiner interface (refiner.h, which describes the
// frame and units). PCL-free (each method converts inside its own .cpp, so
// the heavy PCL templates are compiled once per method, in parallel-friendly
// units).
#pragma once

#include <vector>

#include "core/types.h"
#include "recognition/refine/refiner.h"

namespace pb::refine_detail {

// The leaf size of the crop's kd-tree (the own ICP's nearest-neighbour
// searches and the fitness).
constexpr int kTargetLeafSize = 24;

// Unit normals by PCA over the k nearest neighbours (sign arbitrary: the
// point-to-plane and plane-to-plane metrics do not depend on it).
std::vector<Vec3f> estimate_normals(const std::vector<Vec3f>& pts, int k);

// A refiner's state: the common settings and its own subsection.
template <class Own>
class RefinerWith : public Refiner {
 public:
  RefinerWith(const RegistrationSettings& r, const Own& s) : r_(r), s_(s) {}

 protected:
  RegistrationSettings r_;
  Own s_;
};

}  // namespace pb::refine_detail
