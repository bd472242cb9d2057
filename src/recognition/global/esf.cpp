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
#include "recognition/global/esf_lines.h"

namespace pb {
namespace {

using esf_detail::classified;
using esf_detail::Cls;
using esf_detail::kG;
using esf_detail::kHalf;
using esf_detail::kMixed;
using esf_detail::kOff;
using esf_detail::kOn;
using esf_detail::Line;
using esf_detail::OccupancyGrid;
using esf_detail::trace;
constexpr int kB = kEsfBinsPerHistogram;

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
  bool memoized() const { return !memo_.empty(); }
  Line operator()(int i, int j) {
    if (memo_.empty()) return trace(g_, t_, vox_[static_cast<size_t>(i)], vox_[static_cast<size_t>(j)]);
    uint16_t& m = memo_[static_cast<size_t>(i) * n_ + static_cast<size_t>(j)];
    if (m != 0) return classified(m >> 8, m & 0xff);
    const Line L = trace(g_, t_, vox_[static_cast<size_t>(i)], vox_[static_cast<size_t>(j)]);
    m = static_cast<uint16_t>(L.count << 8 | L.occupied);
    return L;
  }

 private:
  const OccupancyGrid& g_;
  const esf_detail::MoveTable& t_ = esf_detail::move_table();
  const std::vector<Eigen::Vector3i>& vox_;
  size_t n_;
  std::vector<uint16_t> memo_;
};

// The bins of A3's angles: for each bin k >= 1 the smallest |cos| (a float)
// whose bin is below k, found once by bisection over the floats of [0, 1]
// with the formula itself. The formula falls as |cos| grows (acos falls;
// the scaling and the rounding keep order), so a |cos| has bin k or more
// exactly when it lies below edge k: six comparisons instead of acos.
// Checked once over every float from 0 to 1 (results/bench/README.md):
// the table and the formula agree on all 1,065,353,217.
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

namespace {

// A valid triple: its points, their distances |p1p2|, |p1p3|, |p2p3|, the
// squared area, the angle bins at p1, p2, p3.
struct Triple {
  int i[3];
  float d[3];
  float area2;
  int th[3];
};

// What the valid triples add up to: per triple three D2 values with their
// classes, one D3 value with its class; A3 and the D2 ratio are binned
// directly. Counts in integers, turned into PCL's double sums at the end:
// A3 adds line lengths / 32 (sums of multiples of 1/32, exact in double, so
// equal to the integer sum / 32), the others add 1.
struct Samples {
  explicit Samples(int samples) {
    d2.reserve(3 * static_cast<size_t>(samples));
    d2_cls.reserve(3 * static_cast<size_t>(samples));
    d3.reserve(static_cast<size_t>(samples));
    d3_cls.reserve(static_cast<size_t>(samples));
  }
  // The triple with its lines 1->2, 1->3, 2->3.
  void add(const Triple& t, const Line& l12, const Line& l13, const Line& l23) {
    d2.push_back(t.d[0]);
    d2_cls.push_back(static_cast<uint8_t>(l12.cls));
    d2.push_back(t.d[1]);
    d2_cls.push_back(static_cast<uint8_t>(l13.cls));
    d2.push_back(t.d[2]);
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
    d3.push_back(std::sqrt(std::sqrt(t.area2)));
    d3_cls.push_back(static_cast<uint8_t>(tri));
    // Each angle weighted by the length (in voxels) of the opposite line.
    a3_len[tri][static_cast<size_t>(t.th[0])] += l23.count;
    a3_len[tri][static_cast<size_t>(t.th[1])] += l13.count;
    a3_len[tri][static_cast<size_t>(t.th[2])] += l12.count;
  }
  // PCL's histogram of the triples so far (at least one) into out (640
  // values), normalized to sum 1 (left as is when the sum is not positive).
  void histogram(std::vector<float>& out) const {
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
    if (!(sum > 0)) return;
    for (int i = 0; i < kEsfBins; ++i) out[static_cast<size_t>(i)] = static_cast<float>(h[static_cast<size_t>(i)] / sum);
  }

  std::vector<float> d2, d3;
  std::vector<uint8_t> d2_cls, d3_cls;
  std::array<std::array<int64_t, kB>, 3> a3_len{};
  std::array<int64_t, kB> ratio_n{};
};

}  // namespace

namespace {

// The points centred on their centroid and scaled so that the farthest is
// kHalf voxels away (q), their voxels (vox), marked in the grid; false when
// the points all coincide.
bool to_grid(const std::vector<Vec3f>& pts, std::vector<Vec3f>& q, std::vector<Eigen::Vector3i>& vox,
             OccupancyGrid& grid) {
  const int n = static_cast<int>(pts.size());
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const auto& p : pts) c += p.cast<double>();
  c /= n;
  double max_d = 0;
  for (const auto& p : pts) max_d = std::max(max_d, (p.cast<double>() - c).norm());
  if (!(max_d > 0)) return false;
  const double scale = kHalf / max_d;
  q.resize(n);
  vox.resize(n);
  for (int i = 0; i < n; ++i) {
    q[i] = ((pts[i].cast<double>() - c) * scale).cast<float>();
    vox[i] = OccupancyGrid::cell(q[i]);
    grid.mark(vox[i]);
  }
  return true;
}

// The next draw of three points of q: false when it is no valid triple (a
// repeated point, or no area).
bool draw_triple(Rng& rng, const std::vector<Vec3f>& q, const AngleBins& angle_bin, Triple& t) {
  const int n = static_cast<int>(q.size());
  t.i[0] = rng.uniform_int(0, n - 1);
  t.i[1] = rng.uniform_int(0, n - 1);
  t.i[2] = rng.uniform_int(0, n - 1);
  if (t.i[0] == t.i[1] || t.i[0] == t.i[2] || t.i[1] == t.i[2]) return false;
  const Vec3f p1 = q[t.i[0]], p2 = q[t.i[1]], p3 = q[t.i[2]];
  const Vec3f v21 = p2 - p1, v31 = p3 - p1, v23 = p2 - p3;
  const float a = v21.norm(), b = v31.norm(), cc = v23.norm();
  const float s = 0.5f * (a + b + cc);
  t.area2 = s * (s - a) * (s - b) * (s - cc);  // Heron: squared area
  if (!(t.area2 > 0.001f)) return false;
  t.d[0] = a;
  t.d[1] = b;
  t.d[2] = cc;
  // Angles at p1 (between 1->2 and 1->3), at p2 and at p3.
  t.th[0] = angle_bin(std::abs(v21.dot(v31)) / (a * b));
  t.th[1] = angle_bin(std::abs(v23.dot(v21)) / (cc * a));
  t.th[2] = angle_bin(std::abs(v23.dot(v31)) / (cc * b));
  return true;
}

// A batch of triples added with their lines 1->2, 1->3, 2->3 traced
// together (from, to, lines: buffers kept between batches).
void add_traced_together(const OccupancyGrid& grid, const std::vector<Eigen::Vector3i>& vox,
                         const std::vector<Triple>& batch, Samples& acc, std::vector<Eigen::Vector3i>& from,
                         std::vector<Eigen::Vector3i>& to, std::vector<Line>& lines) {
  from.resize(3 * batch.size());
  to.resize(3 * batch.size());
  lines.resize(3 * batch.size());
  for (size_t k = 0; k < batch.size(); ++k) {
    const int* i = batch[k].i;
    from[3 * k] = vox[static_cast<size_t>(i[0])], to[3 * k] = vox[static_cast<size_t>(i[1])];
    from[3 * k + 1] = vox[static_cast<size_t>(i[0])], to[3 * k + 1] = vox[static_cast<size_t>(i[2])];
    from[3 * k + 2] = vox[static_cast<size_t>(i[1])], to[3 * k + 2] = vox[static_cast<size_t>(i[2])];
  }
  esf_detail::trace_lines(grid, from.data(), to.data(), lines.size(), lines.data());
  for (size_t k = 0; k < batch.size(); ++k) acc.add(batch[k], lines[3 * k], lines[3 * k + 1], lines[3 * k + 2]);
}

}  // namespace

std::vector<float> compute_esf(const std::vector<Vec3f>& points_in, Rng& rng, int samples) {
  std::vector<float> out(kEsfBins, 0.f);
  const AngleBins& angle_bin = angle_bins();
  std::vector<Vec3f> pts;
  pts.reserve(points_in.size());
  for (const auto& p : points_in)
    if (p.allFinite()) pts.push_back(p);
  const int n = static_cast<int>(pts.size());
  if (n < 3 || samples <= 0) return out;
  std::vector<Vec3f> q;
  std::vector<Eigen::Vector3i> vox;
  OccupancyGrid grid;
  if (!to_grid(pts, q, vox, grid)) return out;

  Samples acc(samples);
  const long long max_draws = 50LL * samples;
  PairTraces traced(grid, vox, 3LL * samples);
  int valid = 0;
  long long draw = 0;
  if (traced.memoized()) {  // small clouds: each triple's lines looked up (or traced once) as it comes
    for (; valid < samples && draw < max_draws; ++draw) {
      Triple t;
      if (!draw_triple(rng, q, angle_bin, t)) continue;
      acc.add(t, traced(t.i[0], t.i[1]), traced(t.i[0], t.i[2]), traced(t.i[1], t.i[2]));
      ++valid;
    }
  }
  // Otherwise valid triples in batches whose lines are traced together (the
  // draws and their order are those of one triple at a time: a batch holds
  // at most the triples still wanted, so no draw is made that the
  // triple-by-triple loop would not make).
  constexpr int kBatch = 256;
  std::vector<Triple> batch;
  std::vector<Eigen::Vector3i> from, to;
  std::vector<Line> lines;
  while (valid < samples && draw < max_draws) {
    batch.clear();
    const int want = std::min(kBatch, samples - valid);
    for (Triple t; static_cast<int>(batch.size()) < want && draw < max_draws; ++draw)
      if (draw_triple(rng, q, angle_bin, t)) batch.push_back(t);
    add_traced_together(grid, vox, batch, acc, from, to, lines);
    valid += static_cast<int>(batch.size());
  }
  if (valid > 0) acc.histogram(out);
  return out;
}

}  // namespace pb
