// Our FPFH (Rusu et al. 2009) at keypoints, PCL-free, as PCL's
// FPFHEstimation defines it (tests/pcl_reference/fpfh_pcl.cpp keeps PCL's as the reference):
//   - neighbourhoods: every cloud point with squared distance below r^2
//     (FLANN's strict radius), found on the project's kd-tree (KdTree3);
//   - SPFH of every point that is a neighbour of a keypoint: over its
//     neighbours (itself excluded), the three angles f1, f2, f3 of the pair's
//     Darboux frame, 11 bins each, every pair adding 100 / (neighbours - 1);
//   - FPFH of a keypoint: the SPFHs of its neighbours weighted by
//     1 / squared distance (PCL's weighting; coincident points skipped), in
//     order of distance, each of the three histograms scaled to sum 100
//     (tried: summing in kd-tree order saves the sort, a fifth of the time
//     on dense clouds, but moved estimates and turned one bench-pipeline
//     warehouse image wrong, 3121 inliers for a wrong pose against 3100 for
//     the right one: kept in PCL's order).
// Differences from PCL, all at rounding level: those of the pair features
// (recognition/darboux.h).
// A pair of needed points whose two directions give bit-identical features
// is computed once (darboux_pair's `symmetric`). Each keypoint's
// neighbourhood is searched once and serves three times: to find the points
// that need an SPFH, as its own SPFH's list when it needs one, and for its
// weighted sum (one search instead of three). Each row depends on its own
// neighbourhood only and SPFH bins are integer counts: the same result for
// any thread count.
#ifdef _OPENMP
#include <omp.h>
#endif

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

#include "core/atan2_bin.h"
#include "recognition/darboux.h"
#include "recognition/local/internal.h"

namespace pb::local {

namespace {

constexpr int kBins = kSpfhBins;  // per angle

using Hist = std::array<float, kFpfhDim>;
using Counts = std::array<uint32_t, kFpfhDim>;

// This OpenMP thread's number (0 without OpenMP).
inline int thread_num() {
#ifdef _OPENMP
  return omp_get_thread_num();
#else
  return 0;
#endif
}

// The three bins of a pair's features, f1 = atan2(f1_y, f1_x) binned
// without atan2f where the bin is in no doubt (core/atan2_bin.h; the bin
// rises with f1).
inline void count_pair(float f1_y, float f1_x, float f2, float f3, uint32_t* c) {
  ++c[binned_atan2(f1_y, f1_x, [](float f1) { return clamped_bin(kBins * ((f1 + M_PI) * kSpfhInv2Pi), kBins); })];
  ++c[kBins + clamped_bin(kBins * ((f2 + 1.0) * 0.5), kBins)];
  ++c[2 * kBins + clamped_bin(kBins * ((f3 + 1.0) * 0.5), kBins)];
}

// SPFH histograms of the `needed` points (row_of: cloud index -> row, or -1).
// A point with more than max_support neighbours is "thinned": its SPFH is
// taken over an even sample (in tree order) of them, computed by itself
// alone (tried: sharing a pair with a thinned point whose sample holds the
// other, found by a binary search, gave the same rows but made the
// warehouse bench's FPFH description 646 instead of about 420 ms: with 256
// of 2300 neighbours kept few pairs are mutual). Among the other needed
// points each pair is computed once, by the lower index, and counted for
// both when symmetric (darboux_pair), else each point computes its own.
// Counts are integers, so their sum over threads does not depend on the
// order; every addition to a bin of point p adds the same 100 / (pairs of
// p), so the float histogram is that value added count times, as PCL's loop
// adds it.
// Keypoints' neighbourhoods found before (Known): for a needed point that is
// a keypoint its SPFH list is the keypoint's list without the point itself
// (the same thinned set; SPFH counts do not depend on the order), so it is
// not searched again.
struct Known {
  std::vector<int> slot;                                  // cloud index -> keypoint slot, or -1
  std::vector<std::vector<std::pair<float, int>>> lists;  // per slot: thinned, sorted by distance
  std::vector<size_t> found;                              // per slot: neighbours before thinning
};

// The buffers of count_pairs, kept from row to row.
struct PairWork {
  std::vector<uint8_t> decided;
  std::vector<int> bins;
};

// The counts of point p's pairs with todo[j] added to `own` and, where
// todo_row[j] >= 0, to that row's counts in `rows`: their bins eight at a
// time where spfh_pair_bins decides them (symmetric pairs: the same bins
// both ways), the others one at a time with darboux_pair both ways.
void count_pairs(const PointSet& cloud, int p, const std::vector<int>& todo, const std::vector<int>& todo_row,
                 uint32_t* own, std::vector<Counts>& rows, PairWork& work) {
  const std::vector<Vec3f>& pts = cloud.points;
  work.decided.resize(todo.size());
  work.bins.resize(3 * todo.size());
  spfh_pair_bins(cloud, p, todo.data(), todo.size(), work.decided.data(), work.bins.data());
  for (size_t j = 0; j < todo.size(); ++j) {
    const int q = todo[j], qrow = todo_row[j];
    uint32_t* other = qrow >= 0 ? rows[static_cast<size_t>(qrow)].data() : nullptr;
    if (work.decided[j]) {
      const int* b = work.bins.data() + 3 * j;
      ++own[b[0]], ++own[b[1]], ++own[b[2]];
      if (other) ++other[b[0]], ++other[b[1]], ++other[b[2]];
      continue;
    }
    float f1_y, f1_x, f2, f3;
    bool symmetric = false;
    if (darboux_pair(pts[p], cloud.normals[p], pts[q], cloud.normals[q], &f1_y, &f1_x, f2, f3, &symmetric)) {
      count_pair(f1_y, f1_x, f2, f3, own);
      if (other && symmetric) count_pair(f1_y, f1_x, f2, f3, other);
    }
    if (other && !symmetric &&
        darboux_pair(pts[q], cloud.normals[q], pts[p], cloud.normals[p], &f1_y, &f1_x, f2, f3, &symmetric))
      count_pair(f1_y, f1_x, f2, f3, other);
  }
}

// What the SPFH rows are computed from (see spfh_histograms).
struct SpfhInput {
  const PointSet& cloud;
  const CloudNeighbours& tree;
  float r2;
  const std::vector<int>& needed;
  const std::vector<int>& row_of;
  int max_support;
  const Known& known;
};

// The neighbours (the point itself left out) of needed point i, thinned,
// appended to `buf`; true when there were more than max_support.
bool spfh_neighbours(const SpfhInput& in, size_t i, std::vector<std::pair<float, int>>& nn, std::vector<int>& buf) {
  const int p = in.needed[i];
  const int slot = in.known.slot[static_cast<size_t>(p)];
  const std::vector<std::pair<float, int>>* list = &nn;
  size_t found = 0;
  if (slot >= 0) {
    list = &in.known.lists[static_cast<size_t>(slot)];
    found = in.known.found[static_cast<size_t>(slot)];
  } else {
    found = in.tree.within(in.cloud.points[p], in.r2, nn, false, in.max_support);
  }
  for (const auto& e : *list)
    if (e.second != p) buf.push_back(e.second);
  return in.max_support > 0 && found > static_cast<size_t>(in.max_support);
}

// With a cap, which rows are thinned must be known before any pair is
// shared: the lists (at most max_support each) are found first and kept,
// one after the other in a buffer per thread; row i's is
// kept[span[i].thread][span[i].begin, span[i].end).
struct KeptLists {
  struct Span {
    int thread = 0;
    size_t begin = 0, end = 0;
  };
  std::vector<std::vector<int>> kept;
  std::vector<Span> span;
};

KeptLists keep_lists(const SpfhInput& in, int nthreads, std::vector<char>& thinned) {
  const size_t rows = in.needed.size();
  KeptLists k;
  k.kept.resize(static_cast<size_t>(nthreads));
  k.span.resize(rows);
#pragma omp parallel num_threads(nthreads) if (rows > 256)
  {
    const int t = thread_num();
    std::vector<int>& buf = k.kept[static_cast<size_t>(t)];
    std::vector<std::pair<float, int>> nn;
#pragma omp for schedule(dynamic, 64)
    for (long i = 0; i < static_cast<long>(rows); ++i) {
      KeptLists::Span& sp = k.span[static_cast<size_t>(i)];
      sp.thread = t;
      sp.begin = buf.size();
      thinned[static_cast<size_t>(i)] = spfh_neighbours(in, static_cast<size_t>(i), nn, buf);
      sp.end = buf.size();
    }
  }
  return k;
}

// The pairs of point p (its neighbours list[0, len)) that its row computes,
// each with the row that shares it (todo_row, -1: none): a pair of two
// unthinned needed points is computed by the lower index.
void pairs_to_compute(const SpfhInput& in, int p, const int* list, size_t len, bool alone,
                      const std::vector<char>& thinned, std::vector<int>& todo, std::vector<int>& todo_row) {
  todo.clear();
  todo_row.clear();
  for (size_t j = 0; j < len; ++j) {
    const int q = list[j];
    int qrow = in.row_of[static_cast<size_t>(q)];
    if (alone || (qrow >= 0 && thinned[static_cast<size_t>(qrow)])) qrow = -1;  // q counts its own
    if (qrow >= 0 && q < p) continue;  // counted from q
    todo.push_back(q);
    todo_row.push_back(qrow);
  }
}

// The rows' histograms from the threads' counts: each count adds
// 100 / (the row's pairs) to its bin, one addition at a time.
std::vector<Hist> spfh_rows(const std::vector<std::vector<Counts>>& counts, const std::vector<int>& pairs_of) {
  std::vector<Hist> spfhs(pairs_of.size());
  for (size_t i = 0; i < pairs_of.size(); ++i) {
    const float incr = 100.f / static_cast<float>(pairs_of[i]);
    for (int j = 0; j < kFpfhDim; ++j) {
      uint32_t c = 0;
      for (const auto& t : counts)
        if (!t.empty()) c += t[i][static_cast<size_t>(j)];
      float v = 0.f;
      for (uint32_t k = 0; k < c; ++k) v += incr;
      spfhs[i][static_cast<size_t>(j)] = v;
    }
  }
  return spfhs;
}

std::vector<Hist> spfh_histograms(const SpfhInput& in, int nthreads) {
  const size_t rows = in.needed.size();
  std::vector<int> pairs_of(rows, 0);  // neighbours other than the point itself
  std::vector<char> thinned(rows, 0);
  KeptLists kept;
  if (in.max_support > 0) kept = keep_lists(in, nthreads, thinned);
  std::vector<std::vector<Counts>> counts(static_cast<size_t>(nthreads));
#pragma omp parallel num_threads(nthreads) if (rows > 256)
  {
    std::vector<Counts>& mine = counts[static_cast<size_t>(thread_num())];
    mine.assign(rows, Counts{});
    std::vector<std::pair<float, int>> nn;
    std::vector<int> searched, todo, todo_row;
    PairWork pair_work;
#pragma omp for schedule(dynamic, 64)
    for (long i = 0; i < static_cast<long>(rows); ++i) {
      const size_t r = static_cast<size_t>(i);
      const int p = in.needed[r];
      const int* list = searched.data();
      size_t len = 0;
      if (in.max_support > 0) {
        const KeptLists::Span& sp = kept.span[r];
        list = kept.kept[static_cast<size_t>(sp.thread)].data() + sp.begin;
        len = sp.end - sp.begin;
      } else {
        searched.clear();
        spfh_neighbours(in, r, nn, searched);
        list = searched.data();
        len = searched.size();
      }
      pairs_of[r] = static_cast<int>(len);
      // The pairs this row computes, their bins eight at a time where
      // decided (symmetric pairs), the others one at a time.
      pairs_to_compute(in, p, list, len, thinned[r], thinned, todo, todo_row);
      count_pairs(in.cloud, p, todo, todo_row, mine[r].data(), mine, pair_work);
    }
  }
  kept = {};
  return spfh_rows(counts, pairs_of);
}

// The keypoints' slots in `known` (each finite keypoint in range once, in
// order), and their neighbourhoods, thinned evenly in tree order to
// max_support as the SPFH rows are, then put in order of distance (the
// weighted sum follows PCL's order).
void keypoint_neighbourhoods(const std::vector<Vec3f>& pts, const std::vector<int>& keypoints,
                             const CloudNeighbours& tree, float r2, int max_support, int nthreads, Known& known) {
  const int n = static_cast<int>(pts.size());
  known.slot.assign(static_cast<size_t>(n), -1);
  std::vector<int> point_of_slot;
  for (const int k : keypoints) {
    if (k < 0 || k >= n || !pts[k].allFinite() || known.slot[static_cast<size_t>(k)] >= 0) continue;
    known.slot[static_cast<size_t>(k)] = static_cast<int>(point_of_slot.size());
    point_of_slot.push_back(k);
  }
  known.lists.resize(point_of_slot.size());
  known.found.assign(point_of_slot.size(), 0);
#pragma omp parallel for schedule(dynamic, 16) num_threads(nthreads) if (point_of_slot.size() > 64)
  for (long j = 0; j < static_cast<long>(point_of_slot.size()); ++j) {
    const size_t slot = static_cast<size_t>(j);
    known.found[slot] = tree.within(pts[point_of_slot[slot]], r2, known.lists[slot], true, max_support);
  }
}

// One keypoint's FPFH into row: the SPFHs of its neighbours (`list`, in
// order of distance, as PCL) weighted by 1 / squared distance, each of the
// three histograms scaled to sum 100.
void weighted_fpfh(const std::vector<std::pair<float, int>>& list, const std::vector<Hist>& spfhs,
                   const std::vector<int>& row_of, float* row) {
  Hist h{};
  std::array<double, 3> sum{0, 0, 0};
  for (const auto& [d2, q] : list) {
    if (d2 == 0.f) continue;
    const float weight = 1.f / d2;
    const Hist& s = spfhs[static_cast<size_t>(row_of[static_cast<size_t>(q)])];
    // The products first (vectorized), then each histogram's double sum
    // in bin order: the same additions as one loop over the 33 bins.
    std::array<float, kFpfhDim> v;
    for (int j = 0; j < kFpfhDim; ++j) v[j] = s[j] * weight;
    for (int j = 0; j < kFpfhDim; ++j) h[j] += v[j];
    double s0 = sum[0], s1 = sum[1], s2 = sum[2];
    for (int b = 0; b < kBins; ++b) {
      s0 += v[b];
      s1 += v[kBins + b];
      s2 += v[2 * kBins + b];
    }
    sum = {s0, s1, s2};
  }
  for (int j = 0; j < kFpfhDim; ++j) {
    const double total = sum[j / kBins];
    row[j] = static_cast<float>(total != 0 ? h[j] * (100.0 / total) : h[j]);
  }
}

}  // namespace

std::vector<float> compute_fpfh(const PointSet& cloud, const std::vector<int>& keypoints, double radius_mm,
                                int threads, int max_support) {
  std::vector<float> out = undescribed_rows(keypoints.size(), kFpfhDim);
  if (!can_describe(cloud, keypoints, radius_mm)) return out;
  const std::vector<Vec3f>& pts = cloud.points;
  const int n = static_cast<int>(pts.size());
  const CloudNeighbours tree(pts);
  const float r2 = static_cast<float>(radius_mm * radius_mm);
  const int nthreads = omp_threads(threads);

  // Every (finite) keypoint's neighbourhood, found once: it gives which
  // points need an SPFH (every kept neighbour of a keypoint), the keypoint's
  // own SPFH list and its weighted sum below.
  Known known;
  keypoint_neighbourhoods(pts, keypoints, tree, r2, max_support, nthreads, known);
  // The slot of keypoint i, or -1 (out of range or not finite).
  const auto slot_of = [&](size_t i) {
    const int k = keypoints[i];
    return k < 0 || k >= n ? -1 : known.slot[static_cast<size_t>(k)];
  };
  std::vector<int> row_of(static_cast<size_t>(n), -1);
  std::vector<int> needed;
  for (size_t i = 0; i < keypoints.size(); ++i) {
    const int slot = slot_of(i);
    if (slot < 0) continue;
    for (const auto& e : known.lists[static_cast<size_t>(slot)])
      if (row_of[static_cast<size_t>(e.second)] < 0) {
        row_of[static_cast<size_t>(e.second)] = static_cast<int>(needed.size());
        needed.push_back(e.second);
      }
  }
  const std::vector<Hist> spfhs =
      spfh_histograms(SpfhInput{cloud, tree, r2, needed, row_of, max_support, known}, nthreads);

  // FPFH: the weighted SPFHs of each keypoint's neighbours.
#pragma omp parallel num_threads(nthreads) if (keypoints.size() > 64)
  {
#pragma omp for schedule(dynamic, 16)
    for (long i = 0; i < static_cast<long>(keypoints.size()); ++i) {
      const int slot = slot_of(static_cast<size_t>(i));
      if (slot < 0) continue;
      weighted_fpfh(known.lists[static_cast<size_t>(slot)], spfhs, row_of,
                    out.data() + static_cast<size_t>(i) * kFpfhDim);
    }
  }
  return out;
}

}  // namespace pb::local
