// refine_pose: the common frame, crop and bookkeeping around the PCL
// registration methods (one .cpp per method: icp.cpp, icp_lm.cpp,
// icp_plane.cpp, gicp.cpp, ndt.cpp; listed in registry.cpp). See internal.h
// for the frame and units.
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
#include "recognition/registry.h"
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

RefineResult refine_pose(const std::string& method, const PointSet& model, const PointSet& scene,
                         const Pose& init, const RefineSettings& s, uint64_t seed, const KdTree3* scene_tree) {
  const RefinementEntry& entry = refinement_entry(method);

  RefineResult res;
  res.T_cam_model = init;
  const double max_corr = s.max_correspondence_mm;
  if (model.empty() || scene.empty()) return res;
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
  const double margin = s.crop_margin_mm >= 0 ? s.crop_margin_mm : max_corr;
  const double crop_r2 = (radius + margin) * (radius + margin);

  // Scene crop and its centroid: the local frame's origin.
  std::vector<size_t> crop;
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < scene.size(); ++i) {
    const Eigen::Vector3d q = scene.points[i].cast<double>();
    if (!q.allFinite() || (q - centre).squaredNorm() > crop_r2) continue;
    crop.push_back(i);
    c += q;
  }
  if (crop.size() < 3) return res;
  c /= static_cast<double>(crop.size());

  refine_detail::Problem p;
  p.model_diameter_m = box.diagonal().norm() * 1e-3;
  p.src.reserve(model.size());
  for (const auto& q : moved) p.src.push_back(((q - c) * 1e-3).cast<float>());
  p.tgt.reserve(crop.size());
  for (size_t i : crop) p.tgt.push_back(((scene.points[i].cast<double>() - c) * 1e-3).cast<float>());

  // One tree over the crop, for the method's nearest neighbours (a nearest
  // neighbour does not depend on the tree's shape): cut from the scene's
  // tree (its coordinates mapped as p.tgt's are) when given and the crop
  // holds at least half the scene, else built. A cut tree keeps the
  // scene tree's depth: over a small crop its searches are slower (table
  // scenes: crops of a fifth of the scene, about 0.02 ms to build); over
  // most of the scene they are as fast, and cutting costs a seventh of a
  // build (warehouse: crops of 7500 of 11400 points, 0.1 against 0.8 ms;
  // results/bench/README.md).
  if (scene_tree && scene_tree->size() != scene.size())
    throw std::invalid_argument("refine_pose: scene_tree is not over the scene's points");
  const auto local = [&c](int axis, float x) {
    return static_cast<float>((static_cast<double>(x) - c[axis]) * 1e-3);
  };
  const bool cut = scene_tree && 2 * crop.size() >= scene.size();
  const KdTree3 tgt_tree =
      cut ? scene_tree->restricted(crop, p.tgt, local) : KdTree3(p.tgt, refine_detail::kTargetLeafSize);
  p.tgt_tree = &tgt_tree;
  if (entry.run) {
    if (entry.needs_normals(s)) {
      if (model.has_normals()) {
        p.src_normals.reserve(model.size());
        for (const auto& n : model.normals) p.src_normals.push_back((init.R * n.cast<double>()).cast<float>());
      } else {
        p.src_normals = refine_detail::estimate_normals(p.src, s.normal_neighbours);
      }
      if (scene.has_normals()) {
        p.tgt_normals.reserve(crop.size());
        for (size_t i : crop) p.tgt_normals.push_back(scene.normals[i]);
      } else {
        p.tgt_normals = refine_detail::estimate_normals(p.tgt, s.normal_neighbours);
      }
    }
    const refine_detail::Outcome o = entry.run(p, s, seed);
    const Eigen::Matrix4d D = o.delta.cast<double>();
    if (D.allFinite()) {
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
  } else {
    res.converged = true;
  }

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
