// The structured-light model's window sums (render/sensor_noise.cpp): for
// each pixel of a row, the sum of the noisy disparities of the window's
// pixels on the same surface and their count, in row-major window order.
// Several neighbouring pixels are summed side by side in SIMD lanes, each
// lane its own chain in that order, so every instruction set gives the same
// bits as the one-pixel loop. AVX2 is chosen at run time where the CPU has
// it (the build targets plain x86-64), SSE2 otherwise.
#pragma once

#include <cstddef>
#include <cstdint>

namespace pb {

struct WindowSumRow {
  const double* d_cmp;    // true disparity per pixel, +inf where not measured
  const double* d_noisy;  // noisy disparity per pixel, 0 where not measured
  size_t line;            // index of the row's first pixel
  int width;              // pixels per row
  int v0, v1;             // the window's first and last row (clipped to the image)
  int r;                  // window radius: columns u - r .. u + r
  double edge;            // same surface: |d_cmp[q] - d_cmp[p]| not greater than this
};

// Which kernel: the best the CPU has, or SSE2 (for tests comparing them).
enum class WindowSumIsa { best, sse2 };

// Fills sum[u] and count[u] (indexed by column) for u = u_begin, ... in
// steps of the kernel's width while the window stays inside the row
// (u + width - 1 + r < row width); returns the first column not done.
int window_sums(const WindowSumRow& row, int u_begin, double* sum, double* count,
                WindowSumIsa isa = WindowSumIsa::best);

// The depths of pixels [begin, end) of a row from their window sums (same
// column indices): the mean disparity sum / count rounded to a multiple of
// `step` (halves away from zero, core/round.h), then z = fb / that; 0 where
// ok[column] is 0 or the rounded disparity is not positive. Four pixels at
// a time with AVX2 where the CPU has it; the same bits as one at a time.
void depths_from_sums(const double* sum, const double* count, const uint8_t* ok, int begin, int end, double step,
                      double fb, float* z, WindowSumIsa isa = WindowSumIsa::best);

}  // namespace pb
