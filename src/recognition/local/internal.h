// Internal building blocks of the local pipeline (FPFH, SHOT, 3D Hough
// voting). PCL-free: each function converts to PCL types inside its own .cpp
// file, so the PCL compile cost is spread over several small units:
//   keypoints.cpp  keypoints (the shared voxel grid, PCL-free)
//   fpfh.cpp       FPFH (on KdTree3; PCL's, the reference: tests/pcl_reference)
//   shot.cpp       SHOT (on KdTree3; PCL's, the reference: tests/pcl_reference;
//                  shot_votes.cpp: its histogram's votes)
//   match.cpp      descriptor search: a scan with a projected lower bound
//                  (exact for FPFH, SHOT capped by match_max_checks)
//   board.cpp      BOARD reference frames (PCL's, the reference: tests/pcl_reference)
//   hough.cpp      pcl::Hough3DGrouping
//   method.cpp     the Method (train, save/load, hypothesize)
#pragma once

#include <limits>
#include <memory>
#include <vector>

#include "core/types.h"
#include "recognition/cloud.h"
#include "recognition/kdtree.h"

namespace pb::local {

constexpr int kFpfhDim = 33;   // 3 angles x 11 bins
constexpr int kShotDim = 352;  // 8 azimuth x 2 elevation x 2 radial x 11 bins
constexpr int kLrfDim = 9;     // x, y, z axes (rows of R_local_cam)

// Indices into `cloud` of one keypoint per occupied voxel of a grid of edge
// `voxel_mm` (aligned at the origin): the cloud point nearest the centroid of
// the voxel's points, so keypoints are real points and carry normals. Sorted
// by voxel key (deterministic).
std::vector<int> voxel_keypoints(const PointSet& cloud, double voxel_mm);

// SPFH's bins per angle (FPFH: three of them) and count_pair's 1 / (2 pi),
// PCL's float value (fpfh.cpp).
constexpr int kSpfhBins = 11;
constexpr double kSpfhInv2Pi = static_cast<double>(1.0f / (2.0f * static_cast<float>(M_PI)));
// The SPFH bins of darboux_pair(cloud point p, partners[j]) for j < n
// (fpfh_pairs.cpp), eight at a time where the CPU has AVX2: where
// decided[j], the pair is symmetric and its three bins, each histogram's
// offset added, are bins[3 j .. 3 j + 2]; elsewhere (every pair without
// AVX2) the caller computes it one at a time.
void spfh_pair_bins(const PointSet& cloud, int p, const int* partners, size_t n, uint8_t* decided, int* bins);

// Descriptors at `keypoints` (indices into `cloud`) with the whole cloud as
// search surface and its normals (fpfh.cpp, shot.cpp: PCL's definitions,
// our code); row-major, keypoints.size() x dim. Rows that have no
// descriptor (no neighbours, no SHOT reference frame) are NaN.
// threads: OpenMP threads (0 = OMP_NUM_THREADS). The result does not depend on it.
// max_support > 0: a neighbourhood of more points is thinned evenly to that
// many (keep_evenly, kdtree.h) wherever a histogram is summed over it (SHOT:
// the keypoint's, in order of distance, after its frame was computed from
// every point; FPFH: the keypoint's and each SPFH's, in tree order); 0 =
// every point, PCL's definition.
std::vector<float> compute_fpfh(const PointSet& cloud, const std::vector<int>& keypoints,
                                double radius_mm, int threads, int max_support = 0);
std::vector<float> compute_shot(const PointSet& cloud, const std::vector<int>& keypoints,
                                double radius_mm, int threads, int max_support = 0);

// dim NaN values per keypoint: a keypoint descriptor's rows before any is
// described (a keypoint that cannot be keeps its NaN row).
inline std::vector<float> undescribed_rows(size_t keypoints, int dim) {
  return std::vector<float>(keypoints * static_cast<size_t>(dim), std::numeric_limits<float>::quiet_NaN());
}
// Whether keypoints of the cloud can be described at all: there are some,
// the cloud has normals and the radius is positive.
inline bool can_describe(const PointSet& cloud, const std::vector<int>& keypoints, double radius_mm) {
  return !keypoints.empty() && cloud.has_normals() && radius_mm > 0;
}

// OpenMP threads for a `threads` setting: 0 = OMP_NUM_THREADS (as `run`
// gives its workers), 1 without OpenMP.
int omp_threads(int threads);

// Where BOARD's hole search starts counting its 24 angular sectors (the
// frame it finds depends on this axis only through the sector borders).
enum class BoardStartAxis {
  kFixed,  // z x the coordinate axis least aligned with z: deterministic (the pipeline)
  kCRand,  // drawn with std::rand() as PCL draws it (tests, after std::srand)
};
// BOARD local reference frames (Petrelli & Di Stefano 2011, as
// pcl::BOARDLocalReferenceFrameEstimation with holes filled; board.cpp) at
// `keypoints`, cloud as surface; row-major keypoints.size() x 9 (x, y, z
// axes); NaN rows for invalid frames (no frame, not orthonormal). Always
// from the whole neighbourhood: its x axis, the margin point whose normal
// deviates most, moved by tens of degrees in a third of the frames when the
// neighbourhood was thinned to 128 of about 175 points (measured on the
// tests' noisy surface), so it is not thinned.
std::vector<float> compute_board_lrf(const PointSet& cloud, const std::vector<int>& keypoints, double radius_mm,
                                     BoardStartAxis start = BoardStartAxis::kFixed);
// A frame row (x, y, z axes) the voting can use: finite and orthonormal
// within 1e-3.
bool usable_frame(const float* row);

// True if the row holds no NaN / inf.
bool finite_row(const float* row, int dim);

// The finite points of a cloud in a kd-tree, searched by cloud index: the
// neighbourhoods of FPFH, SHOT and the BOARD frames (keypoints.cpp).
class CloudNeighbours {
 public:
  explicit CloudNeighbours(const std::vector<Vec3f>& points);
  // Every finite point with squared distance below r2 (FLANN's strict
  // radius) as (squared distance, cloud index), sorted by distance then
  // index unless `sorted` is false (then in tree order). max_points > 0:
  // more than that many are thinned evenly in tree order (keep_evenly) before
  // the sort. Returns how many there were before thinning.
  size_t within(const Vec3f& q, float r2, std::vector<std::pair<float, int>>& out, bool sorted = true,
                int max_points = 0) const;

 private:
  std::vector<int> cloud_index_;  // tree input index -> cloud index
  KdTree3 tree_;
};

// Nearest neighbour search over descriptors (squared L2 distances): exact
// unless asked otherwise (knn_block's max_checks). Queries are const and
// thread-safe.
class DescriptorIndex {
 public:
  DescriptorIndex();
  ~DescriptorIndex();
  DescriptorIndex(const DescriptorIndex&) = delete;
  DescriptorIndex& operator=(const DescriptorIndex&) = delete;
  // Indexes `rows` rows of `dim` floats (copied).
  void build(const std::vector<float>& data, int dim);
  size_t size() const;
  // Up to k nearest rows with squared L2 distance < max_sq_dist, nearest
  // first (ties by row index).
  void knn(const float* query, int k, float max_sq_dist,
           std::vector<std::pair<int, float>>& out) const;
  // The same for `n` consecutive queries (row-major, n x dim); out[i] gets
  // query i's result, identical to knn(query i). The linear scan streams the
  // indexed rows once per block of queries (cache blocking). max_checks > 0:
  // at most that many rows measured exactly per query, those of the lowest
  // projected bounds, so a row may be missed (approximate search).
  void knn_block(const float* queries, int n, int k, float max_sq_dist,
                 std::vector<std::pair<int, float>>* out, int max_checks = 0) const;
  // Whether the bounds come from the AVX2 kernels (default: where the CPU
  // has AVX2) or, for short rows (FPFH's), from Eigen's product and, for
  // long ones (SHOT's), from a plain loop with the same bits; the answers
  // are the same either way (tests run both).
  void set_avx2_bounds(bool on);
  // Whether long rows (SHOT's), when there are at least 4096, are searched
  // by their clusters (match_clusters.h: bounds only for the rows that can
  // matter; default) or by every row's bound; the same answers either way
  // (tests run both). has_clusters: whether the index has them.
  void set_clusters(bool on);
  bool has_clusters() const;
  // The share of the blocks of bounds a query's likely limit may span by
  // the clusters before it and the block's remaining queries take every
  // row's bound (default 0.4; judged every eight queries; a value over 1:
  // never).
  void set_dense_share(double share);
  // The lower bounds knn_block ranks the rows by, for `n` queries (n x rows,
  // row-major): for tests, which check that every path gives the same bits.
  std::vector<float> lower_bounds(const float* queries, int n) const;

 private:
  void build_projection();
  // lower_bounds into lbs; true when it also wrote each query's smallest
  // bound into mins (n floats; nullptr: not wanted)
  bool bounds(const float* queries, int n, float* lbs, float* mins) const;
  // The same from the queries' projections (n x the axes) and their squared
  // norms.
  bool bounds_projected(const float* zq, const float* zn, int n, float* lbs, float* mins) const;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The `cap` smallest (v[r], r) pairs (value, then index) of v[0..n) among
// those with v[r] <= limit (NaN never), in any order: the candidates of the
// capped search (DescriptorIndex::knn_block's max_checks). avx2: scan with
// the AVX2 kernel, only where the CPU has it (cpu_has_avx2()); the same set.
void smallest_at_most(const float* v, size_t n, float limit, size_t cap, std::vector<std::pair<float, int>>& out,
                      bool avx2 = false);

// A correspondence between a model keypoint (of one training view) and a
// scene keypoint, with its descriptor distance.
struct Match {
  int model = -1;
  int scene = -1;
  float distance = 0;
};

// One Hough cluster: its (PCL-RANSAC-filtered, de-duplicated) matches.
struct HoughCluster {
  std::vector<Match> matches;
};

struct HoughParams {
  double bin_mm = 50.0;     // Hough bin edge
  double min_votes = 5.0;   // bins with at least this many votes are clusters
  bool interpolation = false;  // spread each vote over 8 neighbouring bins
};

// 3D Hough voting (pcl::Hough3DGrouping) of the matches of ONE training view:
// model keypoints with their LRFs vote for the model keypoint centroid in the
// scene. Matches whose model or scene LRF is invalid must be removed before.
std::vector<HoughCluster> hough_grouping(const std::vector<Vec3f>& model_kp,
                                         const std::vector<float>& model_lrf,
                                         const std::vector<Vec3f>& scene_kp,
                                         const std::vector<float>& scene_lrf,
                                         const std::vector<Match>& matches, const HoughParams& p);

// Least-squares rigid transform (Procrustes / Umeyama, no scale) mapping
// model[i] onto scene[i]. Needs >= 3 non-collinear pairs; returns false if
// degenerate.
bool procrustes(const std::vector<Vec3f>& model, const std::vector<Vec3f>& scene, Pose& T_scene_model);

}  // namespace pb::local
