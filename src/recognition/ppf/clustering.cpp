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

std::vector<Hypothesis> cluster_poses(std::vector<PoseVote> poses, const PpfSettings& s) {
  std::vector<Hypothesis> out;
  std::stable_sort(poses.begin(), poses.end(),
                   [](const PoseVote& a, const PoseVote& b) { return a.votes > b.votes; });
  struct Cluster {
    Pose lead;
    Eigen::Quaterniond q_lead;
    Vec3 t_sum = Vec3::Zero();
    Eigen::Vector4d q_sum = Eigen::Vector4d::Zero();
    double votes = 0;
    int members = 0;
    size_t first = 0;
  };
  std::vector<Cluster> clusters;
  const double max_angle = s.rotation_cluster_deg * M_PI / 180.0;
  // A pose joins the first cluster (in creation order) whose lead is within
  // position_cluster_mm and rotation_cluster_deg. The leads are kept in a
  // grid of cells position_cluster_mm wide, so only those of the 27 cells
  // around a pose are tested (a lead nearer than a cell width is in one of
  // them), and the lowest-numbered one that passes is the first. Leads or
  // poses with a non-finite translation (the distance test never rejects
  // them) are tested against every lead, as a scan in creation order would.
  // Cells a little wider than the threshold, so that a rounding of t / cell
  // cannot put two leads nearer than the threshold two cells apart (for
  // |t / cell| < 1e6, where that rounding is below 1e-9 of a cell).
  const double cell = s.position_cluster_mm * (1 + 1e-6);
  const auto cell_of = [cell](const Vec3& t) {
    return std::array<int64_t, 3>{static_cast<int64_t>(std::floor(t.x() / cell)),
                                  static_cast<int64_t>(std::floor(t.y() / cell)),
                                  static_cast<int64_t>(std::floor(t.z() / cell))};
  };
  // Translations farther than 1e6 cells are scanned as the non-finite ones.
  const auto griddable = [cell](const Vec3& t) {
    return t.allFinite() && (t.array().abs() / cell).maxCoeff() < 1e6;
  };
  struct CellHash {
    size_t operator()(const std::array<int64_t, 3>& c) const {
      return static_cast<size_t>((static_cast<uint64_t>(c[0]) * 73856093u) ^
                                 (static_cast<uint64_t>(c[1]) * 19349663u) ^ (static_cast<uint64_t>(c[2]) * 83492791u));
    }
  };
  std::unordered_map<std::array<int64_t, 3>, std::vector<int>, CellHash> grid;  // cell -> its leads' clusters
  std::vector<int> unplaced;                                 // clusters whose lead is not in the grid
  std::vector<int> candidates;
  const auto accepts = [&](const Cluster& c, const PoseVote& pv) {
    if ((pv.pose.t - c.lead.t).norm() >= s.position_cluster_mm) return false;
    const double angle = Eigen::AngleAxisd(c.lead.R.transpose() * pv.pose.R).angle();
    return std::abs(angle) < max_angle;
  };
  for (size_t k = 0; k < poses.size(); ++k) {
    const PoseVote& pv = poses[k];
    const Eigen::Quaterniond q(pv.pose.R);
    int home_index = -1;
    if (griddable(pv.pose.t)) {
      candidates = unplaced;
      const auto c0 = cell_of(pv.pose.t);
      for (int64_t dx = -1; dx <= 1; ++dx)
        for (int64_t dy = -1; dy <= 1; ++dy)
          for (int64_t dz = -1; dz <= 1; ++dz) {
            const auto it = grid.find({c0[0] + dx, c0[1] + dy, c0[2] + dz});
            if (it != grid.end()) candidates.insert(candidates.end(), it->second.begin(), it->second.end());
          }
      std::sort(candidates.begin(), candidates.end());
      for (const int ci : candidates)
        if (accepts(clusters[static_cast<size_t>(ci)], pv)) {
          home_index = ci;
          break;
        }
    } else {
      for (size_t ci = 0; ci < clusters.size(); ++ci)
        if (accepts(clusters[ci], pv)) {
          home_index = static_cast<int>(ci);
          break;
        }
    }
    if (home_index < 0) {
      home_index = static_cast<int>(clusters.size());
      clusters.emplace_back();
      Cluster& c = clusters.back();
      c.lead = pv.pose;
      c.q_lead = q;
      c.first = k;
      if (griddable(pv.pose.t)) grid[cell_of(pv.pose.t)].push_back(home_index);
      else unplaced.push_back(home_index);
    }
    Cluster* home = &clusters[static_cast<size_t>(home_index)];
    home->t_sum += pv.pose.t;
    Eigen::Vector4d qc = q.coeffs();
    if (qc.dot(home->q_lead.coeffs()) < 0) qc = -qc;
    home->q_sum += qc;
    home->votes += pv.votes;
    ++home->members;
  }
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
