// Ensemble of Shape Functions (Wohlkinger and Vincze 2011), our own
// deterministic, thread-safe implementation (PCL's ESFEstimation seeds the
// global generator from the clock). PCL-free; the binning, weights and
// normalization follow PCL's ESFEstimation so the two are comparable (see
// tests/test_recognition_global_esf.cpp).
//
// The cloud is centred on its centroid and scaled so the farthest point lies
// at 32 voxels; a 64^3 occupancy grid marks each point's voxel and its 26
// neighbours. Random point triples (from the Rng passed in) give:
//   D2: the three pairwise distances; each connecting line is traced through
//       the grid (a 3D Bresenham line over max(|dx|,|dy|,|dz|) voxels) and
//       classified ON (all but at most one voxel occupied), OFF (at most 7
//       occupied) or MIXED; D2 ratio: the occupied fraction of MIXED lines;
//   D3: the square root of the triangle's area, classified OFF (at most 21
//       occupied voxels on its three lines), ON (at most 3 free voxels) or
//       MIXED;
//   A3: the three angles (folded to [0, 90] degrees), binned in the
//       triangle's class and weighted by the voxel count of the opposite
//       line / 32.
// Layout (10 x 64 bins): A3 on, off, mixed; D3 on, off, mixed; D2 on, off,
// mixed; D2 ratio, with PCL's weights (0.5 0.5 0.5 0.5 0.5 1 0.5 2 2 1); the
// whole histogram sums to 1. Distances and areas are binned relative to the
// largest sampled value.
#pragma once

#include <vector>

#include "core/random.h"
#include "core/types.h"

namespace pb {

constexpr int kEsfBinsPerHistogram = 64;
constexpr int kEsfBins = 10 * kEsfBinsPerHistogram;  // 640
constexpr int kEsfGridSize = 64;                     // occupancy grid resolution per axis

// ESF of `points` with `samples` valid triples drawn from `rng` (degenerate
// triples, i.e. repeated indices or a squared area <= 0.001 voxel^4, are
// redrawn, at most 50 * samples draws in total). Fewer than 3 distinct
// points, or no valid triple: 640 zeros.
std::vector<float> compute_esf(const std::vector<Vec3f>& points, Rng& rng, int samples = 20000);

// Its binning, exposed for the tests:
// a value in [0, 1] over 64 bins, rounded (std::lround's halves away from
// zero), clamped;
int esf_unit_bin(double v);
// an angle's bin from its |cos|, folded to [0, 90] degrees: the formula,
// esf_unit_bin(acos(clamp(|cos|, 0, 1)) / (pi / 2)), and the same from a
// table of each bin's edge (what compute_esf uses).
int esf_angle_bin_formula(float abs_cos);
int esf_angle_bin(float abs_cos);

}  // namespace pb
