// ICP point-to-point (pcl::IterativeClosestPoint, SVD per iteration), on an
// optional random subset of the source points (thesis: "random subset of
// source points"), drawn from pb::Rng. Frame and units: internal.h.
#include <pcl/registration/icp.h>

#include <algorithm>
#include <numeric>

#include "core/random.h"
#include "recognition/pcl_adapter.h"
#include "recognition/refine/pcl_registration.h"

namespace pb::refine_detail {

namespace {

// The first k of a seeded Fisher-Yates shuffle of the indices, in index order
// (all indices when k is 0 or not below n).
std::vector<size_t> sample_indices(size_t n, int k, uint64_t seed) {
  std::vector<size_t> idx(n);
  std::iota(idx.begin(), idx.end(), size_t(0));
  if (k <= 0 || static_cast<size_t>(k) >= n) return idx;
  Rng rng(seed);
  const size_t kk = static_cast<size_t>(k);
  for (size_t i = 0; i < kk; ++i) {
    const size_t j = i + static_cast<size_t>(rng.uniform_int(0, static_cast<int>(n - i - 1)));
    std::swap(idx[i], idx[j]);
  }
  idx.resize(kk);
  std::sort(idx.begin(), idx.end());
  return idx;
}

}  // namespace

Outcome run_icp(const Problem& p, const RefineSettings& s, uint64_t seed) {
  Counted<pcl::IterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ>> icp;
  const auto src = pcl_adapter::xyz(p.src, sample_indices(p.src.size(), s.icp_sample_points, seed));
  return align<StopReport::kCriteria>(icp, src, pcl_adapter::xyz(p.tgt), s,
               [&](auto& r) { configure_icp_family(r, s); }, no_after_inputs());
}

}  // namespace pb::refine_detail
