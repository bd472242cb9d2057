// Our ESF (see global_esf.h). No global state: the occupancy grid and every
// histogram live on this call's stack/heap, randomness comes from `rng`.
#include "recognition/global/esf.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include "core/round.h"

namespace pb {
namespace {

constexpr int kG = kEsfGridSize;
constexpr int kHalf = kG / 2;
constexpr int kB = kEsfBinsPerHistogram;

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

 private:
  std::vector<uint64_t> bits_;  // one bit per voxel: the whole grid stays in the L1 cache
};

struct Line {
  int count = 0;     // voxels visited
  int occupied = 0;  // of which occupied
  Cls cls = kOff;
  float ratio = 0;   // occupied / count (used for MIXED)
};

// One minor coordinate of the traced line: a + (d i / n rounded to nearest,
// halves up) for i = 0, 1, ..., that is a + floor((2 d i + n) / (2 n)),
// exact in integers for negative d too, kept as a remainder 0 <= rem < 2n.
// |2 d| <= 2 n, so one step moves the coordinate by at most one voxel (by
// `stride` in the grid index; branch-free, masks from the sign bit). It
// defines the lines; the tracing reads its moves from MoveTable.
struct Stepper {
  int rem, step, den, stride;
  Stepper(int d, int n, int stride_) : rem(n), step(2 * d), den(2 * n), stride(stride_) {}  // i = 0: n / 2n = 0 rem n
  int next() {  // the index change of this step
    rem += step;
    const int under = rem >> 31;               // -1 when rem < 0
    const int over = (den - 1 - rem) >> 31;    // -1 when rem >= den
    rem += (under & den) - (over & den);
    return (over & stride) - (under & stride);
  }
};

// The minor axis moves of a line of n steps whose minor coordinate changes
// by d in all: bit i set when step i moves it (by the sign of d), as the
// Stepper takes them. One table for every |d| <= n < kG, built once from
// the Stepper itself, so a line read from it is the Stepper's line. Per
// step, a shift and a multiply instead of the Stepper's remainder update
// (bench_global BM_EsfOurs in alternating runs: results/bench/README.md,
// eleventh round), the same histograms bit for bit (test
// GlobalEsf.HistogramsAreThoseOfTheSteppedLineTracing).
class MoveTable {
 public:
  MoveTable() {
    for (int n = 1; n < kG; ++n)
      for (int d = -n; d <= n; ++d) {
        Stepper s(d, n, 1);
        uint64_t m = 0;
        for (int i = 0; i < n; ++i)
          if (s.next() != 0) m |= uint64_t(1) << i;
        moves_[static_cast<size_t>(n) * (2 * kG + 1) + static_cast<size_t>(d + kG)] = m;
      }
  }
  uint64_t operator()(int d, int n) const {
    return moves_[static_cast<size_t>(n) * (2 * kG + 1) + static_cast<size_t>(d + kG)];
  }

 private:
  std::vector<uint64_t> moves_ = std::vector<uint64_t>(static_cast<size_t>(kG) * (2 * kG + 1), 0);
};

const MoveTable& move_table() {
  static const MoveTable t;
  return t;
}

// A line's class from its counts (ON: all but at most one voxel occupied,
// OFF: at most 7, else MIXED with its occupied fraction).
Line classified(int count, int occupied) {
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

// Traces the line from voxel a toward voxel b: max(|d|) voxels (at least
// one), a included, b excluded, the minor axes rounded to nearest. The major
// axis moves one voxel per step; the two others as their move masks say.
Line trace(const OccupancyGrid& g, const Eigen::Vector3i& a, const Eigen::Vector3i& b) {
  const Eigen::Vector3i d = b - a;
  const Eigen::Vector3i ad = d.cwiseAbs();
  const int n = std::max({ad.x(), ad.y(), ad.z()});
  int idx = OccupancyGrid::index(a.x(), a.y(), a.z());
  if (n == 0) return classified(1, g.occupied(idx) ? 1 : 0);
  const int major = ad.x() == n ? 0 : (ad.y() == n ? 1 : 2);
  const int m1 = major == 0 ? 1 : 0, m2 = major == 2 ? 1 : 2;
  const int major_step = (d[major] > 0 ? 1 : -1) * OccupancyGrid::stride(major);
  const MoveTable& t = move_table();
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

// The traces of ordered point pairs (i, j), from point i's voxel toward
// point j's. A trace depends on the two voxels alone, and `samples` triples
// draw each pair of a small cloud many times (CESF's stable regions: tens to
// hundreds of points, 60,000 traces): there each pair is traced once and
// looked up after, the same counts. Kept where the cloud has no more
// ordered pairs than traces are drawn (at 20,000 triples: up to 245 points;
// then at least a third of the traces are lookups; bench_global
// BM_EsfOurs/150: about 9 -> 6 ms), in a table of 2 bytes per pair:
// count << 8 | occupied, count >= 1, so 0 marks "not traced yet".
class PairTraces {
 public:
  PairTraces(const OccupancyGrid& g, const std::vector<Eigen::Vector3i>& vox, long long traces)
      : g_(g), vox_(vox), n_(vox.size()) {
    static_assert(kG <= 256, "a count and an occupied count fit a byte each");
    if (static_cast<long long>(n_) * static_cast<long long>(n_ - 1) <= traces) memo_.assign(n_ * n_, 0);
  }
  Line operator()(int i, int j) {
    if (memo_.empty()) return trace(g_, vox_[static_cast<size_t>(i)], vox_[static_cast<size_t>(j)]);
    uint16_t& m = memo_[static_cast<size_t>(i) * n_ + static_cast<size_t>(j)];
    if (m != 0) return classified(m >> 8, m & 0xff);
    const Line L = trace(g_, vox_[static_cast<size_t>(i)], vox_[static_cast<size_t>(j)]);
    m = static_cast<uint16_t>(L.count << 8 | L.occupied);
    return L;
  }

 private:
  const OccupancyGrid& g_;
  const std::vector<Eigen::Vector3i>& vox_;
  size_t n_;
  std::vector<uint16_t> memo_;
};

// The bins of A3's angles: for each bin k >= 1 the smallest |cos| (a float)
// whose bin is below k, found once by bisection over the floats of [0, 1]
// with the formula itself. The formula falls as |cos| grows (acos falls;
// the scaling and the rounding keep order), so a |cos| has bin k or more
// exactly when it lies below edge k: six comparisons instead of acos.
// Checked once over every float from 0 to 1 (session 24, results/bench/
// README.md): the table and the formula agree on all 1,065,353,217.
// A |cos| in [0, 1] starts from the lowest bin of its 1/1024th of [0, 1]
// (the bin of that interval's largest float) and steps up while it lies
// below the next edge: the same bin as the bisection, in one or two steps
// but near 1, where the bins crowd.
class AngleBins {
 public:
  AngleBins() {
    auto bits = [](float f) {  // non-negative floats order as their bit patterns
      uint32_t b;
      std::memcpy(&b, &f, sizeof b);
      return b;
    };
    auto from_bits = [](uint32_t b) {
      float f;
      std::memcpy(&f, &b, sizeof f);
      return f;
    };
    edge_[0] = std::numeric_limits<float>::infinity();
    edge_[kB] = -std::numeric_limits<float>::infinity();
    for (int k = 1; k < kB; ++k) {
      uint32_t lo = bits(0.f), hi = bits(1.f);  // bin 63 at 0, bin 0 at 1
      while (hi - lo > 1) {
        const uint32_t mid = lo + (hi - lo) / 2;
        (esf_angle_bin_formula(from_bits(mid)) < k ? hi : lo) = mid;
      }
      edge_[k] = from_bits(hi);
    }
    for (int j = 0; j <= kCells; ++j)  // the largest float of cell j: below (j + 1) / kCells, or 1
      start_[static_cast<size_t>(j)] = static_cast<uint8_t>(
          bisected(j == kCells ? 1.f : std::nextafter(static_cast<float>(j + 1) / kCells, 0.f)));
  }
  int operator()(float abs_cos) const {
    if (!(abs_cos >= 0.f && abs_cos <= 1.f)) return bisected(abs_cos);
    // abs_cos * kCells is exact (a power of two), so its floor is the cell.
    int b = start_[static_cast<size_t>(abs_cos * static_cast<float>(kCells))];
    while (abs_cos < edge_[static_cast<size_t>(b) + 1]) ++b;
    return b;
  }
  // The bin by bisection over the edges (NaN: the formula's).
  int bisected(float abs_cos) const {
    if (std::isnan(abs_cos)) return esf_angle_bin_formula(abs_cos);
    int lo = 0, hi = kB;  // abs_cos < edge_[lo], not < edge_[hi]
    while (hi - lo > 1) {
      const int mid = (lo + hi) / 2;
      (abs_cos < edge_[mid] ? lo : hi) = mid;
    }
    return lo;
  }

 private:
  static constexpr int kCells = 1024;
  std::array<float, kB + 1> edge_{};
  std::array<uint8_t, kCells + 1> start_{};  // the lowest bin of each cell
};

// esf_unit_bin, inline for compute_esf's histogram loops.
inline int unit_bin(double v) {
  const double x = v * (kB - 1);
  // std::lround without its call (core/round.h); NaN and values far outside
  // [0, 1] take the call.
  const long r = std::abs(x) < 1e9 ? static_cast<long>(round_half_away(x)) : std::lround(x);
  return std::clamp(static_cast<int>(r), 0, kB - 1);
}

}  // namespace

int esf_unit_bin(double v) { return unit_bin(v); }

int esf_angle_bin_formula(float abs_cos) {
  const double c = std::clamp(static_cast<double>(abs_cos), 0.0, 1.0);
  return esf_unit_bin(std::acos(c) / (M_PI / 2));
}

namespace {
const AngleBins& angle_bins() {
  static const AngleBins bins;
  return bins;
}
}  // namespace

int esf_angle_bin(float abs_cos) { return angle_bins()(abs_cos); }

std::vector<float> compute_esf(const std::vector<Vec3f>& points_in, Rng& rng, int samples) {
  std::vector<float> out(kEsfBins, 0.f);
  const AngleBins& angle_bin = angle_bins();
  std::vector<Vec3f> pts;
  pts.reserve(points_in.size());
  for (const auto& p : points_in)
    if (p.allFinite()) pts.push_back(p);
  const int n = static_cast<int>(pts.size());
  if (n < 3 || samples <= 0) return out;

  // Centre on the centroid, scale the farthest point to kHalf voxels.
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const auto& p : pts) c += p.cast<double>();
  c /= n;
  double max_d = 0;
  for (const auto& p : pts) max_d = std::max(max_d, (p.cast<double>() - c).norm());
  if (!(max_d > 0)) return out;
  const double scale = kHalf / max_d;
  std::vector<Vec3f> q(n);
  std::vector<Eigen::Vector3i> vox(n);
  OccupancyGrid grid;
  for (int i = 0; i < n; ++i) {
    q[i] = ((pts[i].cast<double>() - c) * scale).cast<float>();
    vox[i] = OccupancyGrid::cell(q[i]);
    grid.mark(vox[i]);
  }

  // Per valid triple: three D2 values with their classes, one D3 value with
  // its class; A3 and the D2 ratio are binned directly.
  std::vector<float> d2;
  std::vector<uint8_t> d2_cls;
  std::vector<float> d3;
  std::vector<uint8_t> d3_cls;
  d2.reserve(3 * static_cast<size_t>(samples));
  d2_cls.reserve(3 * static_cast<size_t>(samples));
  d3.reserve(samples);
  d3_cls.reserve(samples);
  // Counts in integers, turned into PCL's double sums at the end: A3 adds
  // line lengths / 32 (sums of multiples of 1/32, exact in double, so equal
  // to the integer sum / 32), the others add 1.
  std::array<std::array<int64_t, kB>, 3> a3_len{};
  std::array<int64_t, kB> ratio_n{};

  const long long max_draws = 50LL * samples;
  PairTraces traced(grid, vox, 3LL * samples);
  int valid = 0;
  for (long long draw = 0; valid < samples && draw < max_draws; ++draw) {
    const int i1 = rng.uniform_int(0, n - 1);
    const int i2 = rng.uniform_int(0, n - 1);
    const int i3 = rng.uniform_int(0, n - 1);
    if (i1 == i2 || i1 == i3 || i2 == i3) continue;
    const Vec3f v21 = q[i2] - q[i1], v31 = q[i3] - q[i1], v23 = q[i2] - q[i3];
    const float a = v21.norm(), b = v31.norm(), cc = v23.norm();
    const float s = 0.5f * (a + b + cc);
    const float area2 = s * (s - a) * (s - b) * (s - cc);  // Heron: squared area
    if (!(area2 > 0.001f)) continue;

    // Angles at p1 (between 1->2 and 1->3), at p3 and at p2.
    const int th1 = angle_bin(std::abs(v21.dot(v31)) / (a * b));
    const int th3 = angle_bin(std::abs(v23.dot(v31)) / (cc * b));
    const int th2 = angle_bin(std::abs(v23.dot(v21)) / (cc * a));

    const Line l12 = traced(i1, i2);
    const Line l13 = traced(i1, i3);
    const Line l23 = traced(i2, i3);
    d2.push_back(a);
    d2_cls.push_back(static_cast<uint8_t>(l12.cls));
    d2.push_back(b);
    d2_cls.push_back(static_cast<uint8_t>(l13.cls));
    d2.push_back(cc);
    d2_cls.push_back(static_cast<uint8_t>(l23.cls));
    for (const Line* l : {&l12, &l13, &l23})
      if (l->cls == kMixed) ++ratio_n[static_cast<size_t>(unit_bin(l->ratio))];

    const int occ = l12.occupied + l13.occupied + l23.occupied;
    const int cnt = l12.count + l13.count + l23.count;
    Cls tri = kMixed;
    if (occ <= 21)
      tri = kOff;
    else if (cnt - occ < 4)
      tri = kOn;
    d3.push_back(std::sqrt(std::sqrt(area2)));
    d3_cls.push_back(static_cast<uint8_t>(tri));
    // Each angle weighted by the length (in voxels) of the opposite line.
    a3_len[tri][static_cast<size_t>(th1)] += l23.count;
    a3_len[tri][static_cast<size_t>(th2)] += l13.count;
    a3_len[tri][static_cast<size_t>(th3)] += l12.count;
    ++valid;
  }
  if (valid == 0) return out;

  const float max_d2 = *std::max_element(d2.begin(), d2.end());
  const float max_d3 = *std::max_element(d3.begin(), d3.end());
  std::array<std::array<int64_t, kB>, 3> h2_n{}, h3_n{};
  for (size_t i = 0; i < d2.size(); ++i) ++h2_n[d2_cls[i]][static_cast<size_t>(unit_bin(d2[i] / max_d2))];
  for (size_t i = 0; i < d3.size(); ++i) ++h3_n[d3_cls[i]][static_cast<size_t>(unit_bin(d3[i] / max_d3))];
  std::array<std::array<double, kB>, 3> a3{}, h2{}, h3{};
  std::array<double, kB> ratio{};
  for (size_t t = 0; t < 3; ++t)
    for (size_t j = 0; j < kB; ++j) {
      a3[t][j] = static_cast<double>(a3_len[t][j]) / 32.0;
      h2[t][j] = static_cast<double>(h2_n[t][j]);
      h3[t][j] = static_cast<double>(h3_n[t][j]);
    }
  for (size_t j = 0; j < kB; ++j) ratio[j] = static_cast<double>(ratio_n[j]);

  // Concatenation and weights as PCL: A3 on/off/mixed, D3 on/off/mixed, D2
  // on/off/mixed, D2 ratio.
  const std::array<const std::array<double, kB>*, 10> parts = {&a3[kOn], &a3[kOff], &a3[kMixed], &h3[kOn],
                                                               &h3[kOff], &h3[kMixed], &h2[kOn], &h2[kOff],
                                                               &h2[kMixed], &ratio};
  const std::array<double, 10> weights = {0.5, 0.5, 0.5, 0.5, 0.5, 1.0, 0.5, 2.0, 2.0, 1.0};
  std::array<double, kEsfBins> h{};
  double sum = 0;
  for (int k = 0; k < 10; ++k)
    for (int j = 0; j < kB; ++j) {
      h[k * kB + j] = (*parts[k])[j] * weights[k];
      sum += h[k * kB + j];
    }
  if (!(sum > 0)) return out;
  for (int i = 0; i < kEsfBins; ++i) out[i] = static_cast<float>(h[i] / sum);
  return out;
}

}  // namespace pb
