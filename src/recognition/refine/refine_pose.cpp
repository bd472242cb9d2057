// refine_pose: the common frame, crop and bookkeeping around the
// refinement methods (Refiner, refiner.h; one .cpp per method: icp.cpp,
// icp_lm.cpp, icp_pcl.cpp, gicp.cpp, ndt.cpp; listed in registry.cpp). See
// refiner.h for the frame and units.
#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_types.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "core/error.h"
#include "recognition/kdtree.h"
#include "recognition/pcl_adapter.h"
#include "recognition/refine/internal.h"
#include "recognition/refine/refine.h"
#include "recognition/scatter.h"

namespace pb {

namespace refine_detail {

std::vector<Vec3f> estimate_normals(const std::vector<Vec3f>& pts, int k) {
  std::vector<Vec3f> normals(pts.size(), Vec3f(0, 0, 1));
  if (pts.size() < 3) return normals;
  auto cloud = pcl_adapter::xyz(pts);
  pcl::KdTreeFLANN<pcl::PointXYZ> tree;
  tree.setInputCloud(cloud);
  const int kk = std::max(3, std::min<int>(k, static_cast<int>(pts.size())));
  pcl::Indices idx;
  std::vector<float> d2;
  for (size_t i = 0; i < pts.size(); ++i) {
    if (tree.nearestKSearch((*cloud)[i], kk, idx, d2) < 3) continue;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (int j : idx) mean += pts[j].cast<double>();
    mean /= static_cast<double>(idx.size());
    Scatter3 C;
    for (int j : idx) C.add(pts[j].cast<double>() - mean);
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(C.matrix());
    normals[i] = es.eigenvectors().col(0).cast<float>().normalized();
  }
  return normals;
}

}  // namespace refine_detail

namespace {

// The registration problem of one hypothesis: the model at its initial
// pose and the scene's crop around it, in the local frame (refiner.h).
struct Setup {
  RegistrationProblem p;
  std::vector<size_t> crop;  // scene indices of p.tgt
  Eigen::Vector3d c;         // the local frame's origin: the crop's centroid (mm)
};

// False when the crop has fewer than 3 points (nothing to register).
bool crop_scene(const PointSet& model, const PointSet& scene, const Pose& init, const RefineSettings& s, Setup& u) {
  // Model at the initial pose (camera frame, mm), its centre and radius.
  std::vector<Eigen::Vector3d> moved(model.size());
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < model.size(); ++i) {
    moved[i] = init * model.points[i].cast<double>();
    centre += moved[i];
  }
  centre /= static_cast<double>(model.size());
  double radius = 0;
  for (const auto& p : moved) radius = std::max(radius, (p - centre).norm());
  Eigen::AlignedBox3d box;  // in the model frame: independent of the initial pose
  for (const auto& p : model.points) box.extend(p.cast<double>());
  const double margin = s.crop_margin_mm >= 0 ? s.crop_margin_mm : s.max_correspondence_mm;
  const double crop_r2 = (radius + margin) * (radius + margin);

  // Scene crop and its centroid: the local frame's origin.
  u.c = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < scene.size(); ++i) {
    const Eigen::Vector3d q = scene.points[i].cast<double>();
    if (!q.allFinite() || (q - centre).squaredNorm() > crop_r2) continue;
    u.crop.push_back(i);
    u.c += q;
  }
  if (u.crop.size() < 3) return false;
  u.c /= static_cast<double>(u.crop.size());

  u.p.model_diameter_m = box.diagonal().norm() * 1e-3;
  u.p.src.reserve(model.size());
  for (const auto& q : moved) u.p.src.push_back(((q - u.c) * 1e-3).cast<float>());
  u.p.tgt.reserve(u.crop.size());
  for (size_t i : u.crop) u.p.tgt.push_back(((scene.points[i].cast<double>() - u.c) * 1e-3).cast<float>());
  return true;
}

// One tree over the crop, for the method's nearest neighbours (a nearest
// neighbour does not depend on the tree's shape): cut from the scene's tree
// (its coordinates mapped as p.tgt's are) when given and the crop holds at
// least half the scene, else built. A cut tree keeps the scene tree's
// depth: over a small crop its searches are slower (table scenes: crops of
// a fifth of the scene, about 0.02 ms to build); over most of the scene
// they are as fast, and cutting costs a seventh of a build (warehouse:
// crops of 7500 of 11400 points, 0.1 against 0.8 ms; results/bench/README.md).
KdTree3 crop_tree(const Setup& u, const PointSet& scene, const KdTree3* scene_tree) {
  if (scene_tree && scene_tree->size() != scene.size())
    throw std::invalid_argument("refine_pose: scene_tree is not over the scene's points");
  const Eigen::Vector3d& c = u.c;
  const auto local = [&c](int axis, float x) {
    return static_cast<float>((static_cast<double>(x) - c[axis]) * 1e-3);
  };
  const bool cut = scene_tree && 2 * u.crop.size() >= scene.size();
  return cut ? scene_tree->restricted(u.crop, u.p.tgt, local) : KdTree3(u.p.tgt, refine_detail::kTargetLeafSize);
}

// Both clouds' normals in the local frame: the given ones, else by PCA.
void add_normals(const PointSet& model, const PointSet& scene, const Pose& init, const RefineSettings& s, Setup& u) {
  if (model.has_normals()) {
    u.p.src_normals.reserve(model.size());
    for (const auto& n : model.normals) u.p.src_normals.push_back((init.R * n.cast<double>()).cast<float>());
  } else {
    u.p.src_normals = refine_detail::estimate_normals(u.p.src, s.normal_neighbours);
  }
  if (scene.has_normals()) {
    u.p.tgt_normals.reserve(u.crop.size());
    for (size_t i : u.crop) u.p.tgt_normals.push_back(scene.normals[i]);
  } else {
    u.p.tgt_normals = refine_detail::estimate_normals(u.p.tgt, s.normal_neighbours);
  }
}

// The initial pose corrected by the refiner's delta (local frame, metres);
// `res` unchanged when the delta is not finite.
void apply(const RegistrationOutcome& o, const Pose& init, const Eigen::Vector3d& c, RefineResult& res) {
  const Eigen::Matrix4d D = o.delta.cast<double>();
  if (!D.allFinite()) return;
  // Re-orthonormalize the float rotation (SVD projection onto SO(3)).
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(D.block<3, 3>(0, 0), Eigen::ComputeFullU | Eigen::ComputeFullV);
  Mat3 Rd = svd.matrixU() * svd.matrixV().transpose();
  if (Rd.determinant() < 0) {
    Mat3 U = svd.matrixU();
    U.col(2) *= -1;
    Rd = U * svd.matrixV().transpose();
  }
  const Vec3 td = D.block<3, 1>(0, 3) * 1e3;
  // x_cam = c + Rd (R x + t - c) + td
  res.T_cam_model.R = Rd * init.R;
  res.T_cam_model.t = Rd * (init.t - c) + td + c;
  res.converged = o.converged;
  res.iterations = o.iterations;
}

}  // namespace

RefineResult refine_pose(const Refiner* refiner, const PointSet& model, const PointSet& scene, const Pose& init,
                         const RefineSettings& s, uint64_t seed, const KdTree3* scene_tree) {
  RefineResult res;
  res.T_cam_model = init;
  if (model.empty() || scene.empty()) return res;
  Setup u;
  if (!crop_scene(model, scene, init, s, u)) return res;
  const KdTree3 tgt_tree = crop_tree(u, scene, scene_tree);
  u.p.tgt_tree = &tgt_tree;
  if (!refiner) {  // "none": the initial pose
    res.converged = true;
    return res;
  }
  if (refiner->needs_normals()) add_normals(model, scene, init, s, u);
  apply(refiner->align(u.p, seed), init, u.c, res);
  return res;
}

double registration_fitness(const PointSet& model, const PointSet& scene, const Pose& T_cam_model,
                            double max_distance_mm) {
  const double lim = max_distance_mm * max_distance_mm;
  std::vector<Vec3f> finite;
  finite.reserve(scene.size());
  for (const auto& q : scene.points)
    if (q.allFinite()) finite.push_back(q);
  const KdTree3 tree(finite);
  double sum = 0;
  size_t n = 0;
  for (const auto& x : model.points) {
    float d2 = 0;
    if (tree.nearest((T_cam_model * x.cast<double>()).cast<float>(), &d2) < 0) continue;
    if (static_cast<double>(d2) <= lim) {
      sum += static_cast<double>(d2);
      ++n;
    }
  }
  return n > 0 ? sum / static_cast<double>(n) : lim;
}

}  // namespace pb
