// The project's own ICP, point-to-point (icp) and point-to-plane
// (icp_plane): the same algorithm and stopping rules as PCL's
// IterativeClosestPoint / IterativeClosestPointWithNormals (icp_pcl.cpp, kept
// for comparison), with the search structures built once per call instead of
// once per call and iteration:
//   correspondences  every source point's nearest target point within
//                    max_correspondence_mm; reciprocal (optional): the target
//                    point's nearest source point must be that point. The
//                    target tree is built once; the reciprocal search maps
//                    the target point back by the inverse of the current
//                    transform into a source tree built once (distances are
//                    invariant under the rigid transform), where PCL rebuilds
//                    a tree over the moved source on every iteration.
//   step             point-to-point: the least-squares rotation and
//                    translation (SVD of the cross-covariance, Arun / Umeyama
//                    without scale); point-to-plane: linear least squares on
//                    the distances to the targets' tangent planes, small-angle
//                    rotation R = Rz Ry Rx (as PCL's
//                    TransformationEstimationPointToPlaneLLS).
//   stop             PCL's DefaultConvergenceCriteria: the iteration cap;
//                    the step's rotation cosine >= cos(rotation_epsilon) and
//                    squared translation <= transformation_epsilon; the mean
//                    squared correspondence distance changing by less than
//                    fitness_epsilon (relative) or 1e-12 (absolute); fewer
//                    than 3 correspondences ends it unconverged.
// Both use icp.sample_points (a seeded random subset of the source points),
// and, when the source has more than icp.coarse_points points, register in
// two stages: a coarse one on a seeded random subset of icp.coarse_points of
// them, until a stopping rule fires or all but icp.fine_iterations of the
// iteration cap are used, then a fine one on all of them from there, for the
// rest of the cap (the stopping rules start afresh). The total stays within
// max_iterations.
// Frame and units: refiner.h (metres, local frame).
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>

#include "core/random.h"
#include "recognition/kdtree.h"
#include "recognition/refine/internal.h"

namespace pb {

namespace {

using namespace refine_detail;

// Leaf size of ICP's kd-trees (the target's: kTargetLeafSize, internal.h):
// nearest-neighbour queries only, whose answer does not depend on it (ties
// go to the lower index); on the warehouse, 24 points per leaf made
// refinement about 8% faster than the default 8.
constexpr int kIcpLeafSize = kTargetLeafSize;

struct Pair {
  int src, tgt;
  float sq_dist;
};

using Mat4 = Eigen::Matrix4d;

// Correspondences of the source points moved by T (see the file comment).
// `last[i]`: source point i's match of the previous iteration (or -1), the
// target search's starting bound (the same answer, found sooner).
void correspond(const std::vector<Vec3f>& src, const KdTree3& src_tree, const std::vector<Vec3f>& tgt,
                const KdTree3& tgt_tree, const Mat4& T, const RegistrationSettings& s, std::vector<int>& last,
                std::vector<Pair>& out) {
  out.clear();
  const double max_m = s.max_correspondence_mm * 1e-3;
  const float max2 = std::nextafter(static_cast<float>(max_m * max_m), std::numeric_limits<float>::infinity());
  const Eigen::Matrix3f R = T.block<3, 3>(0, 0).cast<float>();
  const Eigen::Vector3f t = T.block<3, 1>(0, 3).cast<float>();
  const Eigen::Matrix3f Ri = R.transpose();
  for (size_t i = 0; i < src.size(); ++i) {
    const Vec3f q = R * src[i] + t;
    float d2 = 0;
    const int j = tgt_tree.nearest(q, &d2, max2, last[i]);
    last[i] = j;
    if (j < 0) continue;
    if (s.reciprocal_correspondences) {
      // Source point i must be the target point's nearest (nearest(back,
      // max2) == i): within the bound and no point preferred to it.
      const Vec3f back = Ri * (tgt[static_cast<size_t>(j)] - t);
      if (!((src[i] - back).squaredNorm() < max2) || src_tree.any_preferred(back, static_cast<int>(i)) >= 0) continue;
    }
    out.push_back({static_cast<int>(i), j, d2});
  }
}

// Point-to-point step: the rigid transform taking the moved source points
// onto their targets in the least-squares sense.
Mat4 step_point(const std::vector<Vec3f>& src, const std::vector<Vec3f>& tgt, const Mat4& T,
                const std::vector<Pair>& c) {
  Vec3 ms = Vec3::Zero(), mt = Vec3::Zero();
  std::vector<Vec3> a(c.size()), b(c.size());
  for (size_t k = 0; k < c.size(); ++k) {
    a[k] = T.block<3, 3>(0, 0) * src[static_cast<size_t>(c[k].src)].cast<double>() + T.block<3, 1>(0, 3);
    b[k] = tgt[static_cast<size_t>(c[k].tgt)].cast<double>();
    ms += a[k];
    mt += b[k];
  }
  ms /= static_cast<double>(c.size());
  mt /= static_cast<double>(c.size());
  Mat3 H = Mat3::Zero();
  for (size_t k = 0; k < c.size(); ++k) H += (a[k] - ms) * (b[k] - mt).transpose();
  Eigen::JacobiSVD<Mat3> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Mat3 V = svd.matrixV();
  Mat3 R = V * svd.matrixU().transpose();
  if (R.determinant() < 0) {
    V.col(2) *= -1;
    R = V * svd.matrixU().transpose();
  }
  Mat4 D = Mat4::Identity();
  D.block<3, 3>(0, 0) = R;
  D.block<3, 1>(0, 3) = mt - R * ms;
  return D;
}

// Point-to-plane step: minimizes sum ((R a + t - b) . n_b)^2 linearized in
// the rotation angles (alpha, beta, gamma about x, y, z).
Mat4 step_plane(const std::vector<Vec3f>& src, const std::vector<Vec3f>& tgt, const std::vector<Vec3f>& tgt_n,
                const Mat4& T, const std::vector<Pair>& c) {
  Eigen::Matrix<double, 6, 6> AtA = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> Atb = Eigen::Matrix<double, 6, 1>::Zero();
  for (const Pair& p : c) {
    const Vec3 a = T.block<3, 3>(0, 0) * src[static_cast<size_t>(p.src)].cast<double>() + T.block<3, 1>(0, 3);
    const Vec3 b = tgt[static_cast<size_t>(p.tgt)].cast<double>();
    const Vec3 n = tgt_n[static_cast<size_t>(p.tgt)].cast<double>();
    Eigen::Matrix<double, 6, 1> row;
    row << a.cross(n), n;
    AtA += row * row.transpose();
    Atb += row * n.dot(b - a);
  }
  const Eigen::Matrix<double, 6, 1> x = AtA.ldlt().solve(Atb);
  Mat4 D = Mat4::Identity();
  D.block<3, 3>(0, 0) = (Eigen::AngleAxisd(x[2], Vec3::UnitZ()) * Eigen::AngleAxisd(x[1], Vec3::UnitY()) *
                         Eigen::AngleAxisd(x[0], Vec3::UnitX()))
                            .toRotationMatrix();
  D.block<3, 1>(0, 3) = x.tail<3>();
  return D;
}

enum class Metric { kPoint, kPlane };

// Iterates from T until a stopping rule fires or `cap` iterations have run
// (o.iterations counts every stage's iterations; o.converged is the last
// stage's).
void iterate(const std::vector<Vec3f>& src, const RegistrationProblem& p, const KdTree3& tgt_tree,
             const RegistrationSettings& s, Metric metric, int cap, Mat4& T, RegistrationOutcome& o) {
  o.converged = false;
  if (cap <= 0 || src.size() < 3) return;
  const KdTree3 src_tree = s.reciprocal_correspondences ? KdTree3(src, kIcpLeafSize) : KdTree3();
  const double rot_cos = std::cos(s.rotation_epsilon_deg * M_PI / 180.0);
  double prev_mse = std::numeric_limits<double>::max();
  std::vector<Pair> c;
  std::vector<int> last(src.size(), -1);
  for (int it = 0; it < cap;) {
    correspond(src, src_tree, p.tgt, tgt_tree, T, s, last, c);
    if (c.size() < 3) break;  // unconverged, the transform so far stands
    const Mat4 D = metric == Metric::kPoint ? step_point(src, p.tgt, T, c) : step_plane(src, p.tgt, p.tgt_normals, T, c);
    if (!D.allFinite()) break;
    T = D * T;
    ++o.iterations;
    if (++it >= cap) break;  // the cap: not converged
    const double cos_angle = 0.5 * (D.block<3, 3>(0, 0).trace() - 1.0);
    if (cos_angle >= rot_cos && D.block<3, 1>(0, 3).squaredNorm() <= s.transformation_epsilon) {
      o.converged = true;
      break;
    }
    double mse = 0;
    for (const Pair& q : c) mse += q.sq_dist;
    mse /= static_cast<double>(c.size());
    if (std::abs(mse - prev_mse) < 1e-12 || std::abs(mse - prev_mse) / prev_mse < s.fitness_epsilon) {
      o.converged = true;
      break;
    }
    prev_mse = mse;
  }
}

// The points sample_indices picks (all of them when k is 0 or not below n).
std::vector<Vec3f> sampled(const std::vector<Vec3f>& pts, int k, uint64_t seed) {
  std::vector<Vec3f> out;
  for (size_t i : sample_indices(pts.size(), k, seed)) out.push_back(pts[i]);
  return out;
}

RegistrationOutcome icp(const RegistrationProblem& p, const RegistrationSettings& r, const IcpSettings& s,
                        uint64_t seed, Metric metric) {
  RegistrationOutcome o;
  const std::vector<Vec3f> src = sampled(p.src, s.sample_points, seed);
  if (src.size() < 3 || p.tgt.size() < 3) return o;
  const KdTree3 own = p.tgt_tree ? KdTree3() : KdTree3(p.tgt, kIcpLeafSize);
  const KdTree3& tgt_tree = p.tgt_tree ? *p.tgt_tree : own;
  Mat4 T = Mat4::Identity();
  int cap = r.max_iterations;
  // Coarse stage: a seeded random subset of the source points, leaving the
  // fine stage at least fine_iterations of the cap.
  const size_t coarse = static_cast<size_t>(std::max(0, s.coarse_points));
  if (coarse >= 3 && src.size() > coarse && cap > s.fine_iterations) {
    const std::vector<Vec3f> sub = sampled(src, static_cast<int>(coarse), derive_seed(seed, {1}));
    iterate(sub, p, tgt_tree, r, metric, cap - s.fine_iterations, T, o);
    cap -= o.iterations;
  }
  iterate(src, p, tgt_tree, r, metric, cap, T, o);
  o.delta = T.cast<float>();
  return o;
}

class IcpRefiner : public Refiner {
 public:
  IcpRefiner(const RegistrationSettings& r, const IcpSettings& s, Metric metric) : r_(r), s_(s), metric_(metric) {}
  bool needs_normals() const override { return metric_ == Metric::kPlane; }
  RegistrationOutcome align(const RegistrationProblem& p, uint64_t seed) const override {
    return icp(p, r_, s_, seed, metric_);
  }

 private:
  RegistrationSettings r_;
  IcpSettings s_;
  Metric metric_;
};

}  // namespace

std::unique_ptr<Refiner> make_icp_refiner(const RegistrationSettings& r, const IcpSettings& s) {
  return std::make_unique<IcpRefiner>(r, s, Metric::kPoint);
}

std::unique_ptr<Refiner> make_icp_plane_refiner(const RegistrationSettings& r, const IcpSettings& s) {
  return std::make_unique<IcpRefiner>(r, s, Metric::kPlane);
}

}  // namespace pb
