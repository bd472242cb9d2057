// Helpers shared by bop_metrics.cpp and bop_metrics_scores.cpp (not an
// interface).
#pragma once

#include <algorithm>
#include <vector>

namespace pb::bop_detail {

// Indices of the estimates of obj_id, by decreasing score (stable), the top k.
inline std::vector<int> top_estimates(const std::vector<double>& scores, const std::vector<int>& objs,
                                      int obj_id, int k) {
  std::vector<int> idx;
  for (size_t i = 0; i < objs.size(); ++i)
    if (objs[i] == obj_id) idx.push_back(static_cast<int>(i));
  std::stable_sort(idx.begin(), idx.end(), [&](int a, int b) { return scores[a] > scores[b]; });
  if (static_cast<int>(idx.size()) > k) idx.resize(k);
  return idx;
}

}  // namespace pb::bop_detail
