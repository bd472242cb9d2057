// Checks of geometric data where it enters (BOP JSON files, camera files):
// each throws InputError naming the file and the field, so a bad value is
// exit 2 with one clear message instead of a silent wrong result later.
#pragma once

#include <string>

#include "core/types.h"

namespace pb {

// Rotation tolerances: |det R - 1| and max |R^T R - I| (elementwise).
// Poses (scene_gt.json) carry 8 or more digits in BOP's own files;
// symmetry transforms in models_info.json are written with about 6
// significant digits in some datasets, so they get a looser bound.
constexpr double kPoseRotationTolerance = 1e-6;
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
