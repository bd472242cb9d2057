// Checks of geometric data where it enters (BOP JSON files, camera files):
// each throws InputError naming the file and the field, so a bad value is
// exit 2 with one clear message instead of a silent wrong result later.
#pragma once

#include <string>

#include "core/types.h"

namespace pb {

// Rotation tolerances: |det R - 1| and max |R^T R - I| (elementwise).
// Poses (scene_gt.json): most BOP datasets carry 8 or more digits, but
// LM-O's ground truth (from the original Occlusion dataset) deviates from a
// rotation by up to 0.0137 (measured over its 1445 test poses), so the bound
// is 0.05: a scaled (mm vs m), mirrored or sheared matrix is still far
// outside it. Accepted matrices are used as written, as bop_toolkit does.
// Symmetry transforms in models_info.json are written with about 6
// significant digits in some datasets.
constexpr double kPoseRotationTolerance = 0.05;
constexpr double kSymmetryRotationTolerance = 1e-4;

// R is a rotation: finite, orthonormal and det +1 within `tolerance`.
void validate_rotation(const Mat3& R, double tolerance, const std::string& file, const std::string& field);

// fx, fy positive and finite, cx, cy finite; with a known image size
// (width, height > 0) also a horizontal and vertical field of view below
// 170 degrees (fx > 0.0437 width: catches intrinsics normalized by the image
// size) and a principal point in [-width, 2 width] x [-height, 2 height].
void validate_intrinsics(const Intrinsics& K, const std::string& file, const std::string& field);

// A 3x3 camera matrix as BOP stores it: [fx 0 cx; 0 fy cy; 0 0 1] (no skew:
// posebench's camera model has none), then validate_intrinsics.
void validate_camera_matrix(const Mat3& K, int width, int height, const std::string& file, const std::string& field);

}  // namespace pb
