// PPF voting and pose clustering (see method.cpp for the algorithm).
#include <pcl/features/pfh_tools.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "core/random.h"
#include "recognition/kdtree.h"
#include "recognition/ppf/internal.h"

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
  if (std::sin(a) * q.z() < 0.0f) a = -a;
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

std::vector<PoseVote> vote(const Model& m, const PointSet& scene, const std::vector<int>& refs) {
  const KdTree3 tree(scene.points);
  const size_t n_model = m.points.size();
  const int n_alpha = std::max(1, static_cast<int>(std::floor(2 * M_PI / m.angle_step)));
  std::vector<uint32_t> acc(n_model * static_cast<size_t>(n_alpha), 0);
  std::vector<uint32_t> touched;  // accumulator cells voted for by the current reference point
  std::vector<PoseVote> poses;
  std::vector<int> nn;
  auto v4 = [](const Vec3f& v) { return Eigen::Vector4f(v.x(), v.y(), v.z(), 0.f); };
  for (int r : refs) {
    const Vec3f sr = scene.points[r], nr = scene.normals[r];
    if (!sr.allFinite() || !nr.allFinite()) continue;
    const Eigen::Affine3f T_sg = to_reference_frame(sr, nr);
    tree.radius_unsorted(sr, m.diameter, nn);  // votes add up: the neighbour order does not matter
    for (uint32_t c : touched) acc[c] = 0;
    touched.clear();
    const Eigen::Vector4f pr = v4(sr), npr = v4(nr);
    for (int i : nn) {
      if (i == r) continue;
      float f1, f2, f3, f4;
      if (!pcl::computePairFeatures(pr, npr, v4(scene.points[static_cast<size_t>(i)]),
                                    v4(scene.normals[static_cast<size_t>(i)]), f1, f2, f3, f4))
        continue;
      if (!std::isfinite(f1) || !std::isfinite(f2) || !std::isfinite(f3) || !std::isfinite(f4)) continue;
      const auto [begin, end] = m.index.find(feature_key(f1, f2, f3, f4, m.angle_step, m.distance_step));
      if (begin == end) continue;
      const float alpha_s = pcl_alpha(T_sg, scene.points[static_cast<size_t>(i)]);
      for (uint32_t e = begin; e < end; ++e) {
        const PairEntry& it = m.table[e];
        float alpha = it.alpha_m - alpha_s;
        if (!std::isfinite(alpha)) continue;
        if (alpha < -M_PI) alpha += static_cast<float>(2 * M_PI);
        else if (alpha > M_PI) alpha -= static_cast<float>(2 * M_PI);
        int bin = static_cast<int>(std::floor((alpha + M_PI) / m.angle_step));
        bin = std::max(0, std::min(n_alpha - 1, bin));
        const uint32_t cell = it.ref * static_cast<uint32_t>(n_alpha) + static_cast<uint32_t>(bin);
        if (acc[cell]++ == 0) touched.push_back(cell);
      }
    }
    if (touched.empty()) continue;
    // The first maximum in cell order (deterministic, as max_element over
    // the whole accumulator).
    uint32_t best_cell = touched[0];
    for (uint32_t c : touched)
      if (acc[c] > acc[best_cell] || (acc[c] == acc[best_cell] && c < best_cell)) best_cell = c;
    const size_t mr = best_cell / static_cast<size_t>(n_alpha);
    const int bin = static_cast<int>(best_cell % static_cast<size_t>(n_alpha));
    const float alpha = static_cast<float>((bin + 0.5) * m.angle_step - M_PI);
    const Eigen::Affine3f T_mg = to_reference_frame(m.points[mr], m.normals[mr]);
    const Eigen::Affine3f T = T_sg.inverse() * Eigen::AngleAxisf(alpha, Vec3f::UnitX()) * T_mg;
    PoseVote pv;
    pv.pose.R = T.linear().cast<double>();
    pv.pose.t = T.translation().cast<double>();
    pv.votes = acc[best_cell];
    poses.push_back(pv);
  }
  return poses;
}

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
  for (size_t k = 0; k < poses.size(); ++k) {
    const PoseVote& pv = poses[k];
    const Eigen::Quaterniond q(pv.pose.R);
    Cluster* home = nullptr;
    for (auto& c : clusters) {
      if ((pv.pose.t - c.lead.t).norm() >= s.position_cluster_mm) continue;
      const double angle = Eigen::AngleAxisd(c.lead.R.transpose() * pv.pose.R).angle();
      if (std::abs(angle) >= max_angle) continue;
      home = &c;
      break;
    }
    if (!home) {
      clusters.emplace_back();
      home = &clusters.back();
      home->lead = pv.pose;
      home->q_lead = q;
      home->first = k;
    }
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
