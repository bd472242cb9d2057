// PPF's greedy pose clustering (see method.cpp for the algorithm), its
// cluster leads kept in a grid so that a pose tests only nearby ones.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "recognition/ppf/internal.h"

namespace pb::ppf {

namespace {

struct Cluster {
  Pose lead;
  Eigen::Quaterniond q_lead;
  Vec3 t_sum = Vec3::Zero();
  Eigen::Vector4d q_sum = Eigen::Vector4d::Zero();
  double votes = 0;
  int members = 0;
  size_t first = 0;
};

using Cell = std::array<int64_t, 3>;

struct CellHash {
  size_t operator()(const Cell& c) const {
    return static_cast<size_t>((static_cast<uint64_t>(c[0]) * 73856093u) ^
                               (static_cast<uint64_t>(c[1]) * 19349663u) ^ (static_cast<uint64_t>(c[2]) * 83492791u));
  }
};

// The clusters of the poses added so far. A pose joins the first cluster
// (in creation order) whose lead is within position_cluster_mm and
// rotation_cluster_deg, else leads a new one. The leads are kept in a grid
// of cells position_cluster_mm wide, so only those of the 27 cells around a
// pose are tested (a lead nearer than a cell width is in one of them), and
// the lowest-numbered one that passes is the first. Leads or poses with a
// non-finite translation (the distance test never rejects them) are tested
// against every lead, as a scan in creation order would.
class PoseClusters {
 public:
  explicit PoseClusters(const PpfSettings& s)
      : s_(s),
        max_angle_(s.rotation_cluster_deg * M_PI / 180.0),
        // Cells a little wider than the threshold, so that a rounding of
        // t / cell cannot put two leads nearer than the threshold two cells
        // apart (for |t / cell| < 1e6, where that rounding is below 1e-9 of
        // a cell).
        cell_(s.position_cluster_mm * (1 + 1e-6)) {}

  // Pose k of the sorted poses into its cluster.
  void add(const PoseVote& pv, size_t k) {
    const Eigen::Quaterniond q(pv.pose.R);
    int home_index = first_accepting(pv);
    if (home_index < 0) home_index = new_cluster(pv, q, k);
    Cluster* home = &clusters_[static_cast<size_t>(home_index)];
    home->t_sum += pv.pose.t;
    Eigen::Vector4d qc = q.coeffs();
    if (qc.dot(home->q_lead.coeffs()) < 0) qc = -qc;
    home->q_sum += qc;
    home->votes += pv.votes;
    ++home->members;
  }

  std::vector<Cluster>& clusters() { return clusters_; }

 private:
  Cell cell_of(const Vec3& t) const {
    return Cell{static_cast<int64_t>(std::floor(t.x() / cell_)), static_cast<int64_t>(std::floor(t.y() / cell_)),
                static_cast<int64_t>(std::floor(t.z() / cell_))};
  }
  // Translations farther than 1e6 cells are scanned as the non-finite ones.
  bool griddable(const Vec3& t) const { return t.allFinite() && (t.array().abs() / cell_).maxCoeff() < 1e6; }
  bool accepts(const Cluster& c, const PoseVote& pv) const {
    if ((pv.pose.t - c.lead.t).norm() >= s_.position_cluster_mm) return false;
    const double angle = Eigen::AngleAxisd(c.lead.R.transpose() * pv.pose.R).angle();
    return std::abs(angle) < max_angle_;
  }

  // The first cluster that accepts the pose, -1 if none.
  int first_accepting(const PoseVote& pv) {
    if (!griddable(pv.pose.t)) {
      for (size_t ci = 0; ci < clusters_.size(); ++ci)
        if (accepts(clusters_[ci], pv)) return static_cast<int>(ci);
      return -1;
    }
    candidates_ = unplaced_;
    const Cell c0 = cell_of(pv.pose.t);
    for (int64_t dx = -1; dx <= 1; ++dx)
      for (int64_t dy = -1; dy <= 1; ++dy)
        for (int64_t dz = -1; dz <= 1; ++dz) {
          const auto it = grid_.find({c0[0] + dx, c0[1] + dy, c0[2] + dz});
          if (it != grid_.end()) candidates_.insert(candidates_.end(), it->second.begin(), it->second.end());
        }
    std::sort(candidates_.begin(), candidates_.end());
    for (const int ci : candidates_)
      if (accepts(clusters_[static_cast<size_t>(ci)], pv)) return ci;
    return -1;
  }

  // A new cluster led by pose k (rotation q); its index.
  int new_cluster(const PoseVote& pv, const Eigen::Quaterniond& q, size_t k) {
    const int index = static_cast<int>(clusters_.size());
    clusters_.emplace_back();
    Cluster& c = clusters_.back();
    c.lead = pv.pose;
    c.q_lead = q;
    c.first = k;
    if (griddable(pv.pose.t)) grid_[cell_of(pv.pose.t)].push_back(index);
    else unplaced_.push_back(index);
    return index;
  }

  const PpfSettings& s_;
  const double max_angle_;
  const double cell_;
  std::vector<Cluster> clusters_;
  std::unordered_map<Cell, std::vector<int>, CellHash> grid_;  // cell -> its leads' clusters
  std::vector<int> unplaced_;                                  // clusters whose lead is not in the grid
  std::vector<int> candidates_;
};

}  // namespace

std::vector<Hypothesis> cluster_poses(std::vector<PoseVote> poses, const PpfSettings& s) {
  std::vector<Hypothesis> out;
  std::stable_sort(poses.begin(), poses.end(),
                   [](const PoseVote& a, const PoseVote& b) { return a.votes > b.votes; });
  PoseClusters grouping(s);
  for (size_t k = 0; k < poses.size(); ++k) grouping.add(poses[k], k);
  std::vector<Cluster>& clusters = grouping.clusters();
  std::stable_sort(clusters.begin(), clusters.end(),
                   [](const Cluster& a, const Cluster& b) { return a.votes > b.votes; });
  if (clusters.size() > static_cast<size_t>(s.max_hypotheses))
    clusters.resize(static_cast<size_t>(s.max_hypotheses));
  for (const auto& c : clusters) {
    Hypothesis h;
    h.T_cam_model.t = c.t_sum / c.members;
    Eigen::Quaterniond q;
    q.coeffs() = c.q_sum.normalized();
    h.T_cam_model.R = q.toRotationMatrix();
    h.score = c.votes;
    out.push_back(h);
  }
  return out;
}

}  // namespace pb::ppf
