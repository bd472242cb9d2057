// Descriptor matching index over the descriptors of all training views:
// exact nearest neighbours under squared L2 distance. Low-dimensional
// descriptors (FPFH, 33) use a FLANN single kd-tree (the index
// pcl::KdTreeFLANN builds). For high-dimensional ones (SHOT, 352) a kd-tree
// visits nearly every leaf (measured: no faster than a linear scan), so they
// use an exact blocked linear scan: the squared distances of a block of
// queries to every row come from one matrix product (|q|^2 + |d|^2 - 2 q.d,
// Eigen's blocked GEMM), which only preselects; every row that can be among
// the k nearest within the product's rounding margin is then measured
// exactly, so the result is the exact scan's, bit for bit. Searches are
// const and thread-safe, and deterministic (no randomized trees).
#include <flann/algorithms/dist.h>
#include <flann/algorithms/kdtree_single_index.h>
#include <flann/util/matrix.h>

#include <Eigen/Core>
#include <algorithm>

#include "recognition/local/internal.h"

namespace pb::local {

namespace {
constexpr int kMaxKdTreeDim = 64;  // above this: linear scan
}

struct DescriptorIndex::Impl {
  std::vector<float> data;
  std::vector<float> sq_norms;  // per row
  float max_sq_norm = 0;
  int dim = 0;
  size_t rows = 0;
  std::unique_ptr<flann::KDTreeSingleIndex<flann::L2_Simple<float>>> index;
};

DescriptorIndex::DescriptorIndex() : impl_(new Impl) {}
DescriptorIndex::~DescriptorIndex() = default;

void DescriptorIndex::build(const std::vector<float>& data, int dim) {
  impl_.reset(new Impl);
  if (dim <= 0 || data.empty()) return;
  impl_->data = data;
  impl_->dim = dim;
  impl_->rows = data.size() / static_cast<size_t>(dim);
  if (dim > kMaxKdTreeDim) {
    impl_->sq_norms.resize(impl_->rows);
    for (size_t r = 0; r < impl_->rows; ++r) {
      const float* d = impl_->data.data() + r * static_cast<size_t>(dim);
      float s = 0;
      for (int j = 0; j < dim; ++j) s += d[j] * d[j];
      impl_->sq_norms[r] = s;
      impl_->max_sq_norm = std::max(impl_->max_sq_norm, s);
    }
    return;
  }
  flann::Matrix<float> m(impl_->data.data(), impl_->rows, static_cast<size_t>(dim));
  impl_->index.reset(new flann::KDTreeSingleIndex<flann::L2_Simple<float>>(
      m, flann::KDTreeSingleIndexParams(15)));
  impl_->index->buildIndex();
}

size_t DescriptorIndex::size() const { return impl_->rows; }

namespace {

// Squared L2 distance with eight fixed partial sums (vectorizable; the same
// summation order every run, whatever the blocking).
inline float sq_dist(const float* a, const float* b, size_t dim) {
  float acc[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  size_t j = 0;
  for (; j + 8 <= dim; j += 8)
    for (int l = 0; l < 8; ++l) {
      const float t = a[j + l] - b[j + l];
      acc[l] += t * t;
    }
  for (; j < dim; ++j) {
    const float t = a[j] - b[j];
    acc[0] += t * t;
  }
  return ((acc[0] + acc[1]) + (acc[2] + acc[3])) + ((acc[4] + acc[5]) + (acc[6] + acc[7]));
}

// Keeps the kk smallest (distance, then row) of the candidates offered, in
// ascending order; rows arrive ascending, so equal distances keep the lower row.
inline void offer(std::vector<std::pair<int, float>>& out, size_t kk, int row, float s) {
  if (out.size() == kk) {
    if (!(s < out.back().second)) return;
    out.pop_back();
  }
  const std::pair<int, float> e(row, s);
  out.insert(std::upper_bound(out.begin(), out.end(), e,
                              [](const auto& a, const auto& b) { return a.second < b.second; }),
             e);
}

}  // namespace

void DescriptorIndex::knn_block(const float* queries, int n, int k, float max_sq_dist,
                                std::vector<std::pair<int, float>>* out) const {
  const size_t dim = static_cast<size_t>(impl_->dim);
  if (impl_->index || impl_->rows == 0 || k <= 0) {
    for (int i = 0; i < n; ++i) knn(queries + static_cast<size_t>(i) * dim, k, max_sq_dist, out[i]);
    return;
  }
  const size_t kk = std::min<size_t>(static_cast<size_t>(k), impl_->rows);
  using RowMat = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  const Eigen::Map<const RowMat> D(impl_->data.data(), static_cast<Eigen::Index>(impl_->rows),
                                   static_cast<Eigen::Index>(dim));
  const Eigen::Map<const RowMat> Q(queries, n, static_cast<Eigen::Index>(dim));
  const RowMat G = Q * D.transpose();  // n x rows dot products
  std::vector<std::pair<float, int>> cand;
  for (int i = 0; i < n; ++i) {
    out[i].clear();
    const float* q = queries + static_cast<size_t>(i) * dim;
    float qn = 0;
    for (size_t j = 0; j < dim; ++j) qn += q[j] * q[j];
    // Rounding margin of the product form (float, dim terms): generous.
    const float margin = 1e-4f * (qn + impl_->max_sq_norm) + 1e-30f;
    cand.clear();
    for (size_t r = 0; r < impl_->rows; ++r) {
      const float approx = qn + impl_->sq_norms[r] - 2.f * G(i, static_cast<Eigen::Index>(r));
      if (approx < max_sq_dist + margin) cand.emplace_back(approx, static_cast<int>(r));
    }
    if (cand.size() > kk) {  // keep the rows that can be among the kk nearest
      std::nth_element(cand.begin(), cand.begin() + static_cast<long>(kk - 1), cand.end());
      const float limit = cand[kk - 1].first + 2.f * margin;
      cand.erase(std::remove_if(cand.begin(), cand.end(), [&](const auto& c) { return c.first > limit; }),
                 cand.end());
    }
    std::sort(cand.begin(), cand.end(), [](const auto& a, const auto& b) { return a.second < b.second; });
    for (const auto& c : cand) {  // ascending rows, exact distances: as the full scan
      const float s = sq_dist(q, impl_->data.data() + static_cast<size_t>(c.second) * dim, dim);
      if (s < max_sq_dist) offer(out[i], kk, c.second, s);
    }
  }
}

void DescriptorIndex::knn(const float* query, int k, float max_sq_dist,
                          std::vector<std::pair<int, float>>& out) const {
  out.clear();
  if (impl_->rows == 0 || k <= 0) return;
  const size_t kk = std::min<size_t>(static_cast<size_t>(k), impl_->rows);
  const size_t dim = static_cast<size_t>(impl_->dim);
  if (!impl_->index) {
    // Exact linear scan; keeps the kk best under the threshold.
    const float* d = impl_->data.data();
    for (size_t r = 0; r < impl_->rows; ++r, d += dim) {
      const float s = sq_dist(query, d, dim);
      if (s < max_sq_dist) offer(out, kk, static_cast<int>(r), s);
    }
    return;
  }
  std::vector<size_t> idx(kk);
  std::vector<float> dist(kk);
  flann::Matrix<float> q(const_cast<float*>(query), 1, dim);
  flann::Matrix<size_t> mi(idx.data(), 1, kk);
  flann::Matrix<float> md(dist.data(), 1, kk);
  flann::SearchParams params(-1, 0.0f, true);
  params.cores = 1;
  const int found = impl_->index->knnSearch(q, mi, md, kk, params);
  for (int i = 0; i < found && i < static_cast<int>(kk); ++i)
    if (dist[i] < max_sq_dist) out.emplace_back(static_cast<int>(idx[i]), dist[i]);
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) {
    return a.second < b.second || (a.second == b.second && a.first < b.first);
  });
}

}  // namespace pb::local
