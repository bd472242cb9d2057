// ESF's occupancy grid and line tracing (global/esf.cpp): a line's voxels
// counted one at a time, or a batch of lines eight at a time where the CPU
// has AVX2, with the same counts. PCL-free.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "recognition/global/esf.h"

namespace pb::esf_detail {

constexpr int kG = kEsfGridSize;
constexpr int kHalf = kG / 2;

enum Cls { kOn = 0, kOff = 1, kMixed = 2 };

class OccupancyGrid {
 public:
  OccupancyGrid() : bits_((static_cast<size_t>(kG) * kG * kG + 63) / 64, 0) {}
  static int cell(float c) { return std::clamp(static_cast<int>(std::floor(c)) + kHalf, 0, kG - 1); }
  static Eigen::Vector3i cell(const Vec3f& p) { return {cell(p.x()), cell(p.y()), cell(p.z())}; }
  // Marks the voxel of p and its 26 neighbours.
  void mark(const Eigen::Vector3i& v) {
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const int x = v.x() + dx, y = v.y() + dy, z = v.z() + dz;
          if (x < 0 || y < 0 || z < 0 || x >= kG || y >= kG || z >= kG) continue;
          const size_t i = index(x, y, z);
          bits_[i >> 6] |= uint64_t(1) << (i & 63);
        }
  }
  int occupied(int i) const { return static_cast<int>((bits_[static_cast<size_t>(i) >> 6] >> (i & 63)) & 1); }
  static int index(int x, int y, int z) { return (x * kG + y) * kG + z; }
  static int stride(int axis) { return axis == 0 ? kG * kG : (axis == 1 ? kG : 1); }

  // The grid as 32-bit words (little-endian: voxel i is bit i % 32 of word
  // i / 32), for the AVX2 gathers.
  const uint32_t* words() const { return reinterpret_cast<const uint32_t*>(bits_.data()); }

 private:
  std::vector<uint64_t> bits_;  // one bit per voxel: the whole grid stays in the L1 cache
};

struct Line {
  int count = 0;     // voxels visited
  int occupied = 0;  // of which occupied
  Cls cls = kOff;
  float ratio = 0;   // occupied / count (used for MIXED)
};

// A line's class from its counts (ON: all but at most one voxel occupied,
// OFF: at most 7, else MIXED with its occupied fraction).
inline Line classified(int count, int occupied) {
  Line L;
  L.count = count;
  L.occupied = occupied;
  if (occupied >= count - 1) {
    L.cls = kOn;
  } else if (occupied <= 7) {
    L.cls = kOff;
  } else {
    L.cls = kMixed;
    L.ratio = static_cast<float>(occupied) / static_cast<float>(count);
  }
  return L;
}

// The minor axis moves of a line of n steps whose minor coordinate changes
// by d in all: bit i set when step i moves it (by the sign of d), as the
// Stepper takes them. One table for every |d| <= n < kG, built once from
// the Stepper itself, so a line read from it is the Stepper's line. Per
// step, a shift and a multiply instead of the Stepper's remainder update
// (measured with bench_global BM_EsfOurs in alternating runs:
// results/bench/README.md), the same histograms bit for bit (test
// GlobalEsf.HistogramsAreThoseOfTheSteppedLineTracing).
class MoveTable {
 public:
  MoveTable();  // from the Stepper (esf_lines.cpp)
  uint64_t operator()(int d, int n) const {
    return moves_[static_cast<size_t>(n) * (2 * kG + 1) + static_cast<size_t>(d + kG)];
  }

 private:
  std::vector<uint64_t> moves_ = std::vector<uint64_t>(static_cast<size_t>(kG) * (2 * kG + 1), 0);
};

// The table, built on first use.
const MoveTable& move_table();

// Traces the line from voxel a toward voxel b: max(|d|) voxels (at least
// one), a included, b excluded, the minor axes rounded to nearest. The major
// axis moves one voxel per step; the two others as their move masks in t
// (move_table()) say. Not inlined: inlined into the small clouds' lookups
// (global/esf.cpp PairTraces) it made them slower (bench_global BM_EsfOurs/50
// 1.21 -> 1.46 ms).
[[gnu::noinline]] inline Line trace(const OccupancyGrid& g, const MoveTable& t, const Eigen::Vector3i& a, const Eigen::Vector3i& b) {
  const Eigen::Vector3i d = b - a;
  const Eigen::Vector3i ad = d.cwiseAbs();
  const int n = std::max({ad.x(), ad.y(), ad.z()});
  int idx = OccupancyGrid::index(a.x(), a.y(), a.z());
  if (n == 0) return classified(1, g.occupied(idx) ? 1 : 0);
  const int major = ad.x() == n ? 0 : (ad.y() == n ? 1 : 2);
  const int m1 = major == 0 ? 1 : 0, m2 = major == 2 ? 1 : 2;
  const int major_step = (d[major] > 0 ? 1 : -1) * OccupancyGrid::stride(major);
  const uint64_t moves1 = t(d[m1], n), moves2 = t(d[m2], n);
  const int step1 = (d[m1] > 0 ? 1 : -1) * OccupancyGrid::stride(m1);
  const int step2 = (d[m2] > 0 ? 1 : -1) * OccupancyGrid::stride(m2);
  int occupied = 0;
  for (int i = 0; i < n; ++i) {
    occupied += g.occupied(idx);
    idx += major_step + static_cast<int>((moves1 >> i) & 1) * step1 + static_cast<int>((moves2 >> i) & 1) * step2;
  }
  return classified(n, occupied);
}

// The lines from[k] -> to[k] for k < n, as trace() gives them: out[k].
// Eight lines at a time where the CPU has AVX2 (unless `plain`), grouped by
// length so that a group's lanes end together.
void trace_lines(const OccupancyGrid& g, const Eigen::Vector3i* from, const Eigen::Vector3i* to, size_t n, Line* out,
                 bool plain = false);

}  // namespace pb::esf_detail
