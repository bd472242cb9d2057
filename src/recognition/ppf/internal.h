// Private pieces of the PPF method (ppf/method.cpp, ppf/voting.cpp): the
// pair feature table, the reference frames of PCL's PPF convention, voting
// and pose clustering. PCL-free (PCL stays in the .cpp files).
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <tuple>
#include <vector>

#include "core/atan2_bin.h"
#include "core/types.h"
#include "recognition/cloud.h"
#include "recognition/ppf/ppf.h"

namespace pb::ppf {

// One model pair in the feature table, with its alpha_m inline (voting
// reads the table sequentially, never the n x n feature matrix).
struct PairEntry {
  uint64_t key;
  uint32_t ref, other;  // model reference point, second point
  float alpha_m = 0;
  bool operator<(const PairEntry& o) const {
    return std::tie(key, ref, other) < std::tie(o.key, o.ref, o.other);
  }
};

// The table's key index: for each distinct key its range [begin, end) of
// the sorted table, in an open-addressing hash (one probe sequence per
// scene pair instead of a binary search over the whole table), and an id of
// its own (its slot).
class KeyIndex {
 public:
  struct Range {
    uint32_t begin = 0, end = 0;  // begin == end: the key is not in the table
    uint32_t id = 0;              // one per key in the table
  };
  void build(const std::vector<PairEntry>& table);
  // Asks for the cache line of `key`'s first slot (a hint: no effect on
  // any result).
  void prefetch(uint64_t key) const {
    if (!keys_.empty()) __builtin_prefetch(keys_.data() + home(key));
  }
  // The range of `key` (begin == end when absent).
  Range find(uint64_t key) const {
    if (keys_.empty()) return {};
    size_t i = home(key);
    while (true) {
      const Slot& s = keys_[i];
      if (s.end == 0) return {};
      if (s.key == key) return {s.begin, s.end, static_cast<uint32_t>(i)};
      i = (i + 1) & (keys_.size() - 1);
    }
  }

 private:
  struct Slot {
    uint64_t key = 0;
    uint32_t begin = 0, end = 0;  // end == 0: empty slot
  };
  size_t home(uint64_t key) const {
    key ^= key >> 29;
    key *= 0xbf58476d1ce4e5b9ull;
    key ^= key >> 32;
    return static_cast<size_t>(key) & (keys_.size() - 1);
  }
  std::vector<Slot> keys_;
};

// The discretized feature (PCL's floor(f / step), in float) packed into 64
// bits, 16 per component (bin indices are clamped to +-32767).
inline int64_t clamped_bin(float floored) {
  return static_cast<int64_t>(std::max(-32767.f, std::min(32767.f, floored)));
}
inline int64_t feature_bin(float f, float step) { return clamped_bin(std::floor(f / step)); }
inline uint64_t pack_key(int64_t b1, int64_t b2, int64_t b3, int64_t b4) {
  auto u = [](int64_t b) { return static_cast<uint64_t>(std::max<int64_t>(-32767, std::min<int64_t>(32767, b)) + 32768) & 0xffffu; };
  return (u(b1) << 48) | (u(b2) << 32) | (u(b3) << 16) | u(b4);
}
inline uint64_t feature_key(float f1, float f2, float f3, float f4, float angle_step, float distance_step) {
  return pack_key(feature_bin(f1, angle_step), feature_bin(f2, angle_step), feature_bin(f3, angle_step),
                  feature_bin(f4, distance_step));
}

// feature_bin(std::atan2(y, x), step) without atan2f where the bin is in no
// doubt (core/atan2_bin.h).
inline int64_t atan2_bin(float y, float x, float step) {
  return binned_atan2(y, x, [step](float a) { return feature_bin(a, step); });
}

// std::sin(a) * z < 0.0f for an angle a of atan2f (|a| <= the float nearest
// pi, 3.14159274, which lies beyond pi), without sinf: sinf's sign is a's,
// but at +-3.14159274, where it is the opposite (sinf(3.14159274f) is
// -8.7e-8). With |a| and |z| at least 1e-20 the product cannot round to
// zero (|sinf(a)| >= min(|a|, 8.7e-8)); smaller values, NaN and anything
// beyond 3.14159274 take sinf.
inline bool sin_times_negative(float a, float z) {
  constexpr float kPi = static_cast<float>(M_PI);
  const float abs_a = std::fabs(a);
  if (abs_a >= 1e-20f && abs_a <= kPi && std::fabs(z) >= 1e-20f) {
    const bool sin_positive = (a > 0) != (abs_a == kPi);
    return sin_positive ? z < 0 : z > 0;
  }
  return std::sin(a) * z < 0.0f;
}

// The keys a scene pair looks up (Vidal et al. 2018): its own bin and, per
// component whose value lies within `margin` of a bin (a fraction of it)
// from an edge, also the bin across that edge; every combination (at most
// 16), own bin first. margin 0: the own bin only.
int neighbour_keys(const float f[4], const float step[4], float margin, uint64_t out[16]);

// The trained model: downsampled merged views (model frame, mm), the n x n
// pair features (row = reference point) and the pairs sorted by feature key.
// One ordered model pair's feature (pcl::PPFSignature's values): the angles
// f1..f3, the distance f4 (mm) and the angle alpha_m of the second point
// about the reference point's normal.
struct PairFeature {
  float f1 = 0, f2 = 0, f3 = 0, f4 = 0, alpha_m = 0;
};

struct Model {
  std::vector<Vec3f> points, normals;
  std::vector<PairFeature> features;
  std::vector<PairEntry> table;  // empty: nothing to match
  // What voting reads of table[e], in the table's order and in two arrays
  // (8 bytes an entry where PairEntry has 24, so the ranges a scene pair
  // looks up stay in cache; eight of each load at once): its reference
  // point and its alpha_m.
  std::vector<uint32_t> vote_ref;
  std::vector<float> vote_alpha;
  KeyIndex index;                 // over table
  float angle_step = 0, distance_step = 0, diameter = 0;
};

// The feature table of m.features (every model pair with a defined
// feature, sorted by key, then by pair, so equal keys come in a fixed
// order), its voting arrays and its key index. Fewer than three points or
// features not n x n: an empty table (nothing to match).
void build_table(Model& m);

struct PoseVote {
  Pose pose;
  double votes = 0;
};

// PCL's pair feature (pcl::computePairFeatures, bit for bit): f[0..2] the
// angles f1..f3 of the pair's Darboux frame, f[3] the distance; false (and
// zeros) when the points coincide or the frame is degenerate. The source
// point is the one whose normal makes the smaller angle with the line, PCL's
// acos comparison, taken from |cos| where the two differ by far more than
// acos's rounding (acos is decreasing with slope at most -1 on [0, 1]).
// Dot products are summed in the order of Eigen's four-lane SSE reduction,
// (x + z) + (y + 0), as PCL's Vector4f code sums them.
bool pair_feature(const Vec3f& p1, const Vec3f& n1, const Vec3f& p2, const Vec3f& n2, float f[4]);
// pair_feature but its first angle: f[1..3] as pair_feature, and f[0]'s
// arguments, f[0] = std::atan2(*y, *x) (f[0] left as is; on false, as
// pair_feature, every f[k] 0 and *y, *x unset).
bool pair_feature_parts(const Vec3f& p1, const Vec3f& n1, const Vec3f& p2, const Vec3f& n2, float f[4], float* y,
                        float* x);
// pcl::computePairFeatures itself (tests: the reference of pair_feature).
bool pcl_pair_feature(const Vec3f& p1, const Vec3f& n1, const Vec3f& p2, const Vec3f& n2, float f[4]);

// The key of a scene pair (PCL's pair feature binned: f1's bin from
// atan2_bin, the others' from feature_bin, packed): false where the pair
// has no feature (coincident points, a degenerate frame, a NaN).
bool pair_key(const Vec3f& sr, const Vec3f& nr, const Vec3f& p, const Vec3f& n, const float step[4], uint64_t* key);
// The keys of reference point (sr, nr) paired with scene points
// partners[0..n) (a partner equal to `self` skipped), in order: the pairs
// with a key in out_point[0..m), their keys in out_key[0..m) (each room
// for n); returns m. Eight pairs at a time where the CPU has AVX2, the same
// bits as pair_keys_plain, one at a time with pair_key.
size_t pair_keys(const Vec3f& sr, const Vec3f& nr, const PointSet& scene, const int* partners, size_t n, int self,
                 const float step[4], int* out_point, uint64_t* out_key);
size_t pair_keys_plain(const Vec3f& sr, const Vec3f& nr, const PointSet& scene, const int* partners, size_t n,
                       int self, const float step[4], int* out_point, uint64_t* out_key);

// Rigid transform taking point p to the origin and the unit normal n onto
// +x (PCL's PPF convention).
Eigen::Affine3f to_reference_frame(const Vec3f& p, const Vec3f& n);

// Rotation angle of a point about +x in its reference frame, with the signs
// of PCL's alpha_m / alpha_s (alpha = alpha_m - alpha_s aligns the model
// pair with the scene pair).
float pcl_alpha(const Eigen::Affine3f& T, const Vec3f& other);

// The seeded subset of scene reference points (ascending indices).
std::vector<int> reference_points(size_t n, double fraction, uint64_t seed);

// alpha_s of the pairs of the reference point whose frame is T with the
// points idx[0..n) of `pts` (pcl_alpha(T, pts.points[idx[k]])), where only
// its bins count: value[k] the series' angle (core/atan2_bin.h) as a float,
// within 2 * kAtan2BinWindow of pcl_alpha's; bin[k] the vote flags' bin of
// pcl_alpha's value, floor((alpha_s + pi) / step) in double, where the
// window leaves no doubt, else -1 (also for a zero or non-finite argument,
// an angle within the window of +-pi, where atan2f may give +-float(pi) and
// pcl_alpha negates it, and everywhere without AVX2): there, take
// pcl_alpha itself. The cells of an approximate value come from
// VoteCells::checked.
void approx_alpha_s(const Eigen::Affine3f& T, const PointSet& pts, const int* idx, size_t n, float step,
                    float* value, int* bin);

// PCL's alpha bin value of a vote: (alpha + pi) / step in double, as float.
inline float alpha_bin_value(float alpha, float angle_step) {
  return static_cast<float>((alpha + M_PI) / angle_step);
}

// The alpha bin of a vote, floor(alpha_bin_value) clamped to [0, n), without
// the double division: that map is non-decreasing in alpha (every step of it
// is), so each bin's first float, found once by bisection, tells the bin
// after a guess by multiplication.
class AlphaBins {
 public:
  AlphaBins(float angle_step, int n);
  int operator()(float alpha) const {
    int b = static_cast<int>((alpha + static_cast<float>(M_PI)) * scale_);
    b = std::max(0, std::min(n_ - 1, b));
    while (alpha >= first_[static_cast<size_t>(b) + 1]) ++b;
    while (alpha < first_[static_cast<size_t>(b)]) --b;
    return b;
  }
  int exact(float alpha) const;  // the same from the formula (finite alpha)

 private:
  float step_;
  int n_;
  std::vector<float> first_;  // first_[k]: the smallest float of bin k; first_[0] -inf, first_[n] +inf
  float scale_ = 0;
};

// alpha = alpha_m - alpha_s brought into [-pi, pi] (PCL's wrap: one turn
// added below -pi, else one taken above pi).
inline float wrapped_alpha(float alpha_m, float alpha_s) {
  float alpha = alpha_m - alpha_s;
  if (alpha < -M_PI) alpha += static_cast<float>(2 * M_PI);
  else if (alpha > M_PI) alpha -= static_cast<float>(2 * M_PI);
  return alpha;
}

// The accumulator cells of one scene pair's votes without neighbouring
// bins: for each of the n model pairs, cells[k] = ref[k] * n_alpha +
// bins(wrapped_alpha(alpha_m[k], alpha_s)). The same bits on every CPU:
// eight pairs at a time where it has AVX2 (the bin from its formula,
// AlphaBins::exact, in double as PCL's; the last block masked), else one at
// a time with AlphaBins.
class VoteCells {
 public:
  VoteCells(float angle_step, int n_alpha);
  void operator()(const uint32_t* ref, const float* alpha_m, size_t n, float alpha_s, uint32_t* cells) const;
  // The one-at-a-time path alone (tests: the reference of the AVX2 one).
  void plain(const uint32_t* ref, const float* alpha_m, size_t n, float alpha_s, uint32_t* cells) const;
  // operator()'s cells from an approximate alpha_s (approx_alpha_s' value):
  // true when they are the cells of every alpha_s within 2 *
  // kAtan2BinWindow of it, the exact one among them (no vote's bin value
  // within the reach of that window, plus the roundings, of a bin edge, and
  // no vote's alpha of the wrap at +-pi);
  // false: the cells are not to be used. Always false without AVX2.
  bool checked(const uint32_t* ref, const float* alpha_m, size_t n, float alpha_s, uint32_t* cells) const;

 private:
  float step_;
  int n_alpha_;
  float edge_margin_;  // checked's: the reach in bin values
  AlphaBins bins_;
  bool avx2_;
};

// How a scene pair votes (PpfSettings::neighbour_margin, vote_once).
struct VoteOptions {
  float margin = 0;        // neighbouring feature bins and alpha bins within this fraction of an edge
  bool vote_once = false;  // one vote per (reference, model key, alpha_s bin)
};

// One pose per reference point: the best accumulator cell of its votes.
// Reference r is scene.points[r]; its partners are the points of
// `partners` within the model's diameter (nullptr: of `scene`, r skipped).
std::vector<PoseVote> vote(const Model& m, const PointSet& scene, const std::vector<int>& refs,
                           const VoteOptions& opt, const PointSet* partners = nullptr);

// Greedy clustering, most votes first; the best max_hypotheses clusters as
// hypotheses (mean translation, sign-aligned mean quaternion, summed votes).
std::vector<Hypothesis> cluster_poses(std::vector<PoseVote> poses, const PpfSettings& s);

}  // namespace pb::ppf
