// The voxel grid's packed cell keys (voxel_grid.cpp), one per point: each
// axis's cell index floor(p * (1 / leaf)) or floor(p / leaf) minus the
// grid's lowest cell, in as few bits as that axis's span needs, the axis of
// highest priority in the highest bits, so that the keys' order is the order
// of the cell triples. Four points at a time with AVX2 where the CPU has it
// (the build targets plain x86-64): the same divisions and products in
// double, floor as floor, so every instruction set gives the same keys as
// the one-point loop. Internal to the preprocessing stage; PCL-free.
#pragma once

#include <cstddef>
#include <cstdint>

#include "core/types.h"

namespace pb::detail {

// A key no cell has: the point is not finite.
constexpr uint64_t kNoCell = ~uint64_t(0);

struct PackedGrid {
  double leaf = 1;       // the voxel's side (mm)
  bool divide = false;   // cell index from p / leaf (true) or p * (1 / leaf)
  int axis[3] = {2, 1, 0};   // the point's coordinate per key field, highest priority first
  int64_t lo[3] = {0, 0, 0};  // the lowest cell index per key field
  int shift[3] = {0, 0, 0};   // each field's position in the key (the last one's is 0)
  // Every finite point's cell indices lie within int32 (the four-lane path
  // converts them as such); false: the one-point loop for all.
  bool int32_cells = false;
};

enum class KeyIsa { best, scalar };

// keys[i] for points[0, n): the packed key of point i's cell, or kNoCell if
// a coordinate is not finite. Requires every finite point's cell offsets to
// fit their fields (the caller sizes the fields from the points' box).
void packed_cell_keys(const Vec3f* points, size_t n, const PackedGrid& g, uint64_t* keys,
                      KeyIsa isa = KeyIsa::best);

// The box of the finite points of points[0, n) (a point with any coordinate
// NaN or infinite is left out): lo and hi per coordinate x, y, z. Four
// points at a time (SSE, baseline x86-64). Returns false, and lo > hi, if
// no point is finite.
bool finite_box(const Vec3f* points, size_t n, float lo[3], float hi[3]);

// floor(x) as an integer, for finite x in range: the same value as
// std::floor without a libm call (baseline x86-64 has no rounding
// instruction).
inline int64_t floor_to_int(double x) {
  const int64_t i = static_cast<int64_t>(x);  // truncates toward zero
  return static_cast<double>(i) > x ? i - 1 : i;
}

}  // namespace pb::detail
