// PPF voting (see method.cpp for the algorithm; the pose clustering is in
// clustering.cpp).
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>

#include "core/random.h"
#include "recognition/kdtree.h"
#include "recognition/ppf/internal.h"
#include "recognition/ppf/vote_state.h"

namespace pb::ppf {

// Rigid transform taking point p to the origin and the unit normal n onto
// +x (PCL's PPF convention).
Eigen::Affine3f to_reference_frame(const Vec3f& p, const Vec3f& n) {
  const float angle = std::acos(std::max(-1.0f, std::min(1.0f, n.dot(Vec3f::UnitX()))));
  const bool parallel = n.y() == 0.0f && n.z() == 0.0f;
  const Vec3f axis = parallel ? Vec3f::UnitY() : Vec3f(n.cross(Vec3f::UnitX()).normalized());
  const Eigen::AngleAxisf rot(angle, axis);
  return Eigen::Affine3f(Eigen::Translation3f(rot * (-p)) * rot);
}

// Rotation angle of a point about +x in its reference frame, with the signs
// of PCL's alpha_m / alpha_s (alpha = alpha_m - alpha_s aligns the model
// pair with the scene pair).
float pcl_alpha(const Eigen::Affine3f& T, const Vec3f& other) {
  const Vec3f q = T * other;
  float a = std::atan2(-q.z(), q.y());
  if (sin_times_negative(a, q.z())) a = -a;
  return -a;
}

std::vector<int> reference_points(size_t n, double fraction, uint64_t seed) {
  std::vector<int> refs(n);
  std::iota(refs.begin(), refs.end(), 0);
  const size_t n_refs = std::max<size_t>(1, static_cast<size_t>(std::lround(fraction * static_cast<double>(n))));
  if (n_refs < refs.size()) {
    Rng rng(seed);
    for (size_t i = 0; i < n_refs; ++i) {
      const size_t j = i + static_cast<size_t>(rng.uniform_int(0, static_cast<int>(refs.size() - i - 1)));
      std::swap(refs[i], refs[j]);
    }
    refs.resize(n_refs);
    std::sort(refs.begin(), refs.end());
  }
  return refs;
}

void build_table(Model& m) {
  m.table.clear();
  m.vote_ref.clear();
  m.vote_alpha.clear();
  const size_t n = m.points.size();
  if (n < 3 || m.features.size() != n * n) {
    m.index.build(m.table);
    return;
  }
  m.table.reserve(m.features.size());
  for (size_t i = 0; i < n; ++i)
    for (size_t j = 0; j < n; ++j) {
      const auto& f = m.features[i * n + j];
      if (i == j || !std::isfinite(f.f1) || !std::isfinite(f.f2) || !std::isfinite(f.f3) || !std::isfinite(f.f4) ||
          !std::isfinite(f.alpha_m))
        continue;
      m.table.push_back({feature_key(f.f1, f.f2, f.f3, f.f4, m.angle_step, m.distance_step),
                         static_cast<uint32_t>(i), static_cast<uint32_t>(j), f.alpha_m});
    }
  std::sort(m.table.begin(), m.table.end());
  m.vote_ref.resize(m.table.size());
  m.vote_alpha.resize(m.table.size());
  for (size_t e = 0; e < m.table.size(); ++e) {
    m.vote_ref[e] = m.table[e].ref;
    m.vote_alpha[e] = m.table[e].alpha_m;
  }
  m.index.build(m.table);
}

void KeyIndex::build(const std::vector<PairEntry>& table) {
  keys_.clear();
  size_t distinct = 0;
  for (size_t i = 0; i < table.size(); ++i) distinct += i == 0 || table[i].key != table[i - 1].key;
  if (distinct == 0) return;
  size_t cap = 16;
  while (cap < 2 * distinct) cap *= 2;
  keys_.assign(cap, Slot{});
  for (size_t b = 0; b < table.size();) {
    size_t e = b;
    while (e < table.size() && table[e].key == table[b].key) ++e;
    size_t i = home(table[b].key);
    while (keys_[i].end != 0) i = (i + 1) & (cap - 1);
    keys_[i] = Slot{table[b].key, static_cast<uint32_t>(b), static_cast<uint32_t>(e)};
    b = e;
  }
}

int neighbour_keys(const float f[4], const float step[4], float margin, uint64_t out[16]) {
  int64_t bins[4][2];
  int n[4];
  for (int k = 0; k < 4; ++k) {
    const float b = f[k] / step[k];
    const float own = std::floor(b);
    bins[k][0] = clamped_bin(own);  // feature_bin(f[k], step[k]), from the one division
    n[k] = 1;
    if (margin > 0) {
      const float frac = b - own;
      if (frac < margin) bins[k][n[k]++] = bins[k][0] - 1;
      else if (frac > 1 - margin) bins[k][n[k]++] = bins[k][0] + 1;
    }
  }
  int count = 0;
  for (int a = 0; a < n[0]; ++a)
    for (int b = 0; b < n[1]; ++b)
      for (int c = 0; c < n[2]; ++c)
        for (int d = 0; d < n[3]; ++d) out[count++] = pack_key(bins[0][a], bins[1][b], bins[2][c], bins[3][d]);
  return count;
}

namespace {

// The votes of one scene pair's model pairs [begin, end) with neighbouring
// alpha bins (margin > 0): PCL's bin value, its fraction decides the
// neighbour.
template <class Acc>
void vote_with_margin(const Model& m, uint32_t begin, uint32_t end, float alpha_s, int n_alpha, float margin,
                      Acc& acc) {
  for (uint32_t e = begin; e < end; ++e) {
    const float alpha = wrapped_alpha(m.vote_alpha[e], alpha_s);
    if (!std::isfinite(alpha)) continue;
    const float b = alpha_bin_value(alpha, m.angle_step);
    const float floored = std::floor(b);
    const int bin = std::max(0, std::min(n_alpha - 1, static_cast<int>(floored)));
    const uint32_t cell = m.vote_ref[e] * static_cast<uint32_t>(n_alpha);
    acc.add(cell + static_cast<uint32_t>(bin));
    const float frac = b - floored;  // the neighbouring alpha bin (alpha wraps around)
    if (frac < margin) acc.add(cell + static_cast<uint32_t>((bin + n_alpha - 1) % n_alpha));
    else if (frac > 1 - margin) acc.add(cell + static_cast<uint32_t>((bin + 1) % n_alpha));
  }
}

}  // namespace

AlphaBins::AlphaBins(float angle_step, int n) : step_(angle_step), n_(n), first_(static_cast<size_t>(n) + 1) {
  // Floats in order as integers (-0 and +0 both 0: they bin alike).
  auto ord = [](float f) {
    int32_t b;
    std::memcpy(&b, &f, sizeof b);
    return b < 0 ? -static_cast<int64_t>(b & 0x7fffffff) : static_cast<int64_t>(b);
  };
  auto from_ord = [](int64_t o) {
    const uint32_t b = o < 0 ? (static_cast<uint32_t>(-o) | 0x80000000u) : static_cast<uint32_t>(o);
    float f;
    std::memcpy(&f, &b, sizeof f);
    return f;
  };
  first_[0] = -std::numeric_limits<float>::infinity();
  first_[static_cast<size_t>(n)] = std::numeric_limits<float>::infinity();
  for (int k = 1; k < n; ++k) {  // the first float of bin k: bisection between -8 (bin 0) and 8 (bin n - 1)
    int64_t lo = ord(-8.f), hi = ord(8.f);
    while (hi - lo > 1) {
      const int64_t mid = lo + (hi - lo) / 2;
      (exact(from_ord(mid)) >= k ? hi : lo) = mid;
    }
    first_[static_cast<size_t>(k)] = from_ord(hi);
  }
  scale_ = 1.0f / angle_step;
}

int AlphaBins::exact(float alpha) const {
  return std::max(0, std::min(n_ - 1, static_cast<int>(std::floor(alpha_bin_value(alpha, step_)))));
}

namespace {

// The keys of reference point (sr, nr) paired with each of `partners` but
// itself, with neighbouring bins (Vidal et al.'s margin > 0): per pair with
// a feature its point, its keys appended to `keys`, their end.
void margin_pair_keys(const Vec3f& sr, const Vec3f& nr, const PointSet& scene, const std::vector<int>& partners,
                      int self, const float step[4], float margin, std::vector<int>& pair_point,
                      std::vector<uint64_t>& keys, std::vector<uint32_t>& pair_keys_end) {
  uint64_t margin_keys[16];
  for (int i : partners) {
    if (i == self) continue;
    float f[4], y0, x0;
    if (!pair_feature_parts(sr, nr, scene.points[static_cast<size_t>(i)], scene.normals[static_cast<size_t>(i)], f,
                            &y0, &x0))
      continue;
    // f[0] = atan2(y0, x0) is finite unless an argument is NaN.
    if (std::isnan(y0) || std::isnan(x0) || !std::isfinite(f[1]) || !std::isfinite(f[2]) || !std::isfinite(f[3]))
      continue;
    f[0] = std::atan2(y0, x0);  // the bins' fractions count: the angle itself
    const int n_keys = neighbour_keys(f, step, margin, margin_keys);
    pair_point.push_back(i);
    keys.insert(keys.end(), margin_keys, margin_keys + n_keys);
    pair_keys_end.push_back(static_cast<uint32_t>(keys.size()));
  }
}

// The keys of reference point (sr, nr) paired with each of `partners` but
// `self`: per pair with a feature its point and the end of its keys in
// `keys` (with a margin, Vidal et al.'s neighbouring bins; without, one key
// per pair, its own bin).
void reference_keys(const Vec3f& sr, const Vec3f& nr, const PointSet& scene, const std::vector<int>& partners,
                    int self, const float step[4], float margin, std::vector<int>& pair_point,
                    std::vector<uint64_t>& keys, std::vector<uint32_t>& pair_keys_end) {
  pair_point.clear();
  pair_keys_end.clear();
  keys.clear();
  if (margin > 0) {
    margin_pair_keys(sr, nr, scene, partners, self, step, margin, pair_point, keys, pair_keys_end);
    return;
  }
  pair_point.resize(partners.size());
  keys.resize(partners.size());
  const size_t n_pairs =
      pair_keys(sr, nr, scene, partners.data(), partners.size(), self, step, pair_point.data(), keys.data());
  pair_point.resize(n_pairs);
  keys.resize(n_pairs);
  pair_keys_end.resize(n_pairs);
  std::iota(pair_keys_end.begin(), pair_keys_end.end(), 1u);
}

// The pose of the best accumulator cell (model reference point, alpha bin,
// the bin's centre) for the scene reference frame T_sg, with its votes.
PoseVote cell_pose(const Model& m, const Eigen::Affine3f& T_sg, const BestCell& best, int n_alpha) {
  const uint32_t cell = best.cell();
  const size_t mr = cell / static_cast<size_t>(n_alpha);
  const int bin = static_cast<int>(cell % static_cast<size_t>(n_alpha));
  const float alpha = static_cast<float>((bin + 0.5) * m.angle_step - M_PI);
  const Eigen::Affine3f T_mg = to_reference_frame(m.points[mr], m.normals[mr]);
  const Eigen::Affine3f T = T_sg.inverse() * Eigen::AngleAxisf(alpha, Vec3f::UnitX()) * T_mg;
  PoseVote pv;
  pv.pose.R = T.linear().cast<double>();
  pv.pose.t = T.translation().cast<double>();
  pv.votes = best.votes();
  return pv;
}

// One reference point's pairs: the second point of each, the end of its
// keys in `keys`, each key's range in the table (and its id), and for the
// pairs whose key is in the table (one key per pair) approx_alpha_s' values
// and bins.
struct ReferencePairs {
  std::vector<int> pair_point;
  std::vector<uint32_t> pair_keys_end;
  std::vector<uint64_t> keys;
  std::vector<KeyIndex::Range> ranges;
  std::vector<int> hit_point;
  std::vector<float> hit_alpha;
  std::vector<int> hit_bin;
};

// One reference point's pairs (rp, in order) vote into acc: alpha_s once a
// pair's key is in the table (a pair whose keys all miss casts no vote,
// whatever its alpha_s; approx_alpha_s' value where it gave a bin), the
// flags, then the cells of the model pairs of its key.
template <class Acc>
void cast_votes(const Model& m, const VoteOptions& opt, const ReferencePairs& rp, const Eigen::Affine3f& T_sg,
                const PointSet& partners, const VoteCells& vote_cells, int n_alpha, VoteFlags& flags, Acc& acc) {
  constexpr size_t kRangesAhead = 8;  // each range's first entries prefetched this many keys ahead
  constexpr uint32_t kChunk = 256;    // cells computed at a time
  uint32_t cells[kChunk];
  const uint32_t* const vote_ref = m.vote_ref.data();
  const float* const vote_alpha = m.vote_alpha.data();
  const KeyIndex::Range* const ranges = rp.ranges.data();
  const size_t n_ranges = rp.ranges.size(), n_pairs = rp.pair_point.size();
  const bool margin = opt.margin > 0, vote_once = opt.vote_once;
  size_t hit = 0, q = 0;
  for (size_t p = 0; p < n_pairs; ++p) {
    const size_t i = static_cast<size_t>(rp.pair_point[p]);
    float alpha_s = 0;
    int alpha_s_bin = 0;
    bool have_alpha_s = false, approximate = false;
    for (; q < rp.pair_keys_end[p]; ++q) {
      if (q + kRangesAhead < n_ranges) {
        const uint32_t ahead = ranges[q + kRangesAhead].begin;
        __builtin_prefetch(vote_ref + ahead);
        __builtin_prefetch(vote_alpha + ahead);
      }
      const auto [begin, end, id] = ranges[q];
      if (begin == end) continue;
      if (!have_alpha_s) {
        have_alpha_s = true;
        if (!margin && rp.hit_bin[hit] >= 0) {  // approximate: its bins are pcl_alpha's
          alpha_s = rp.hit_alpha[hit];
          alpha_s_bin = rp.hit_bin[hit++];
          approximate = true;
        } else {
          hit += !margin;
          alpha_s = pcl_alpha(T_sg, partners.points[i]);
          if (!std::isfinite(alpha_s)) {
            q = rp.pair_keys_end[p];
            break;
          }
          alpha_s_bin = static_cast<int>(std::floor((alpha_s + M_PI) / m.angle_step));
        }
      }
      if (vote_once && !flags.first(id, alpha_s_bin)) continue;
      if (margin) {
        vote_with_margin(m, begin, end, alpha_s, n_alpha, opt.margin, acc);
        continue;
      }
      // alpha_m and alpha_s are finite (the table holds finite ones), so
      // alpha is.
      for (uint32_t e = begin; e < end; e += kChunk) {
        const uint32_t n = std::min(kChunk, end - e);
        if (!approximate || !vote_cells.checked(vote_ref + e, vote_alpha + e, n, alpha_s, cells)) {
          if (approximate) {  // a vote near a bin edge: pcl_alpha decides (finite: its arguments are)
            alpha_s = pcl_alpha(T_sg, partners.points[i]);
            approximate = false;
          }
          vote_cells(vote_ref + e, vote_alpha + e, n, alpha_s, cells);
        }
        for (uint32_t c = 0; c < n; ++c) acc.add(cells[c]);
      }
    }
  }
}

}  // namespace

std::vector<PoseVote> vote(const Model& m, const PointSet& scene, const std::vector<int>& refs,
                           const VoteOptions& opt, const PointSet* partner_cloud) {
  // The partners: `scene` itself (a reference skips its own index) or a
  // cloud of their own (nothing skipped: a partner at the reference's very
  // position has no feature).
  const PointSet& partners = partner_cloud ? *partner_cloud : scene;
  const KdTree3 tree(partners.points);
  const size_t n_model = m.points.size();
  const int n_alpha = std::max(1, static_cast<int>(std::floor(2 * M_PI / m.angle_step)));
  const VoteCells vote_cells(m.angle_step, n_alpha);
  Accumulator acc(n_model * static_cast<size_t>(n_alpha));
  SmallAccumulator small(n_model * static_cast<size_t>(n_alpha));
  std::vector<PoseVote> poses;
  std::vector<int> nn;
  VoteFlags flags;
  const float step[4] = {m.angle_step, m.angle_step, m.angle_step, m.distance_step};
  // One reference's pairs in three passes, so that the table's memory is
  // asked for ahead of its use (on a real frame the key index and the
  // table's ranges are beyond the caches): the keys of every pair, their
  // ranges in the index (its slots prefetched kSlotsAhead keys ahead), then
  // the votes (cast_votes; each range's first entries prefetched ahead).
  // Pairs and keys keep their order, so the votes and the flags are those
  // of one pass.
  constexpr size_t kSlotsAhead = 16;
  ReferencePairs rp;
  for (int r : refs) {
    const Vec3f sr = scene.points[r], nr = scene.normals[r];
    if (!sr.allFinite() || !nr.allFinite()) continue;
    const Eigen::Affine3f T_sg = to_reference_frame(sr, nr);
    const int self = partner_cloud ? -1 : r;
    // The kd-tree's order of the partners: deterministic, and with vote_once
    // it counts (the first pair of a (key, alpha_s bin) votes, with its own
    // alpha_s).
    tree.radius_unsorted(sr, m.diameter, nn);
    flags.next_reference();
    reference_keys(sr, nr, partners, nn, self, step, opt.margin, rp.pair_point, rp.keys, rp.pair_keys_end);
    const std::vector<uint64_t>& keys = rp.keys;
    rp.ranges.resize(keys.size());
    for (size_t q = 0; q < keys.size(); ++q) {
      if (q + kSlotsAhead < keys.size()) m.index.prefetch(keys[q + kSlotsAhead]);
      rp.ranges[q] = m.index.find(keys[q]);
    }
    // One key per pair: alpha_s of the pairs whose key is in the table, eight
    // at a time, approximately where its bins leave no doubt (approx_alpha_s),
    // and the most votes the reference can cast, the sum of their ranges.
    rp.hit_point.clear();
    uint64_t votes_bound = 0;
    if (opt.margin <= 0)
      for (size_t p = 0; p < rp.pair_point.size(); ++p)
        if (rp.ranges[p].begin != rp.ranges[p].end) {
          rp.hit_point.push_back(rp.pair_point[p]);
          votes_bound += rp.ranges[p].end - rp.ranges[p].begin;
        }
    rp.hit_alpha.resize(rp.hit_point.size());
    rp.hit_bin.resize(rp.hit_point.size());
    approx_alpha_s(T_sg, partners, rp.hit_point.data(), rp.hit_point.size(), m.angle_step, rp.hit_alpha.data(),
                   rp.hit_bin.data());
    // Its votes: counted in 16 bits where they cannot overflow them.
    if (opt.margin <= 0 && votes_bound <= SmallAccumulator::kMaxVotes) {
      small.next_reference();
      cast_votes(m, opt, rp, T_sg, partners, vote_cells, n_alpha, flags, small);
      if (small.best().votes() > 0) poses.push_back(cell_pose(m, T_sg, small.best(), n_alpha));
    } else {
      acc.next_reference();
      cast_votes(m, opt, rp, T_sg, partners, vote_cells, n_alpha, flags, acc);
      if (acc.best().votes() > 0) poses.push_back(cell_pose(m, T_sg, acc.best(), n_alpha));
    }
  }
  return poses;
}

}  // namespace pb::ppf
