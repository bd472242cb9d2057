// Descriptor matching index: FLANN single kd-tree (exact search, squared L2,
// the same index pcl::KdTreeFLANN builds), over the descriptors of all
// training views. Searches are const and thread-safe.
#include <flann/algorithms/dist.h>
#include <flann/algorithms/kdtree_single_index.h>
#include <flann/util/matrix.h>

#include <algorithm>

#include "recognition/local_internal.h"

namespace pb::local {

struct DescriptorIndex::Impl {
  std::vector<float> data;
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
  flann::Matrix<float> m(impl_->data.data(), impl_->rows, static_cast<size_t>(dim));
  impl_->index.reset(new flann::KDTreeSingleIndex<flann::L2_Simple<float>>(
      m, flann::KDTreeSingleIndexParams(15)));
  impl_->index->buildIndex();
}

size_t DescriptorIndex::size() const { return impl_->rows; }

void DescriptorIndex::knn(const float* query, int k, float max_sq_dist,
                          std::vector<std::pair<int, float>>& out) const {
  out.clear();
  if (!impl_->index || k <= 0) return;
  const size_t kk = std::min<size_t>(static_cast<size_t>(k), impl_->rows);
  std::vector<size_t> idx(kk);
  std::vector<float> dist(kk);
  flann::Matrix<float> q(const_cast<float*>(query), 1, static_cast<size_t>(impl_->dim));
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
