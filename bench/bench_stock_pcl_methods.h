// Stock PCL versions of the recognition methods, for bench_stock_pcl.cpp
// only (the one file that includes PCL outside src/recognition). Every step
// is the plain PCL call the PCL tutorials make, one object per step, at the
// project's settings. Clouds are in metres, PCL's customary unit (OUR-CVFH
// even hard-codes a 1 cm sigma): every *_mm setting is multiplied by kM.
//   preprocess   depth -> cloud, PassThrough (range), VoxelGrid,
//                SACSegmentation + ExtractIndices (plane), NormalEstimation
//   fpfh / shot  UniformSampling keypoints, FPFHEstimation / SHOTEstimation,
//                KdTreeFLANN matching (k = 1), BOARD frames, Hough3DGrouping
//                per training view
//   cvfh / esf   EuclideanClusterExtraction, CVFHEstimation / ESFEstimation,
//                KdTreeFLANN matching, CRHEstimation + CRHAlignment (roll)
//   ourcvfh      the same with OURCVFHEstimation and its reference frames
//   ppf          PPFEstimation + PPFHashMapSearch (offline), PPFRegistration
//   refinement   IterativeClosestPoint per hypothesis against the whole scene,
//                then the most inliers (KdTreeFLANN nearest neighbour) wins
#pragma once

#include <pcl/common/centroid.h>
#include <pcl/common/io.h>
#include <pcl/common/transforms.h>
#include <pcl/features/board.h>
#include <pcl/features/crh.h>
#include <pcl/features/cvfh.h>
#include <pcl/features/esf.h>
#include <pcl/features/fpfh.h>
#include <pcl/features/normal_3d.h>
#include <pcl/features/our_cvfh.h>
#include <pcl/features/ppf.h>
#include <pcl/features/shot.h>
#include <pcl/filters/extract_indices.h>
#include <pcl/filters/filter.h>
#include <pcl/filters/passthrough.h>
#include <pcl/filters/uniform_sampling.h>
#include <pcl/filters/voxel_grid.h>
#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/recognition/cg/hough_3d.h>
#include <pcl/recognition/crh_alignment.h>
#include <pcl/registration/icp.h>
#include <pcl/registration/ppf_registration.h>
#include <pcl/segmentation/extract_clusters.h>
#include <pcl/segmentation/sac_segmentation.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <type_traits>
#include <vector>

#include "recognition/settings.h"

namespace stock {

using Point = pcl::PointXYZ;
using Cloud = pcl::PointCloud<Point>;
using Normals = pcl::PointCloud<pcl::Normal>;
using Tree = pcl::search::KdTree<Point>;
using Mat4 = Eigen::Matrix4f;
using Crh = pcl::PointCloud<pcl::Histogram<90>>;
constexpr float kM = 0.001f;  // mm -> m

// A preprocessed cloud: points, normals, and one kd-tree over the points that
// every estimator on this cloud shares (PCL rebuilds it only for a new cloud).
struct Prepared {
  Cloud::Ptr cloud{new Cloud};
  Normals::Ptr normals{new Normals};
  Tree::Ptr tree{new Tree};
};

// A pose hypothesis: T_cam_model (metres), the training view it came from.
struct Hyp {
  Mat4 T;
  int view = 0;
  double score = 0;
};

inline Prepared preprocess(const Cloud::Ptr& raw, const pb::PreprocessSettings& s, bool scene) {
  // Range cut: pcl::PassThrough on z.
  Cloud::Ptr cut(new Cloud), grid(new Cloud);
  pcl::PassThrough<Point> pass;
  pass.setInputCloud(raw);
  pass.setFilterFieldName("z");
  pass.setFilterLimits(float(s.min_range_mm * kM), float(s.max_range_mm * kM));
  pass.filter(*cut);
  // Downsampling: pcl::VoxelGrid (one centroid per occupied voxel).
  pcl::VoxelGrid<Point> vg;
  vg.setInputCloud(cut);
  const float leaf = float(s.voxel_mm * kM);
  vg.setLeafSize(leaf, leaf, leaf);
  vg.filter(*grid);
  // Dominant plane (scenes only): pcl::SACSegmentation (RANSAC, plane model);
  // pcl::ExtractIndices keeps the other points.
  const size_t n0 = grid->size();
  for (int k = 0; scene && s.remove_plane && k < s.max_planes && grid->size() >= 3; ++k) {
    pcl::SACSegmentation<Point> seg;
    seg.setOptimizeCoefficients(true);
    seg.setModelType(pcl::SACMODEL_PLANE);
    seg.setMethodType(pcl::SAC_RANSAC);
    seg.setDistanceThreshold(s.plane_threshold_mm * kM);
    seg.setMaxIterations(s.plane_iterations);
    seg.setInputCloud(grid);
    pcl::PointIndices::Ptr inliers(new pcl::PointIndices);
    pcl::ModelCoefficients coefficients;
    seg.segment(*inliers, coefficients);
    if (double(inliers->indices.size()) < s.min_plane_fraction * double(n0)) break;
    pcl::ExtractIndices<Point> extract;
    extract.setInputCloud(grid);
    extract.setIndices(inliers);
    extract.setNegative(true);
    Cloud::Ptr rest(new Cloud);
    extract.filter(*rest);
    grid = rest;
  }
  // Normals: pcl::NormalEstimation, kd-tree radius search, flipped toward the
  // camera at the origin (PCL's default viewpoint).
  Prepared p;
  Normals all;
  pcl::NormalEstimation<Point, pcl::Normal> ne;
  ne.setInputCloud(grid);
  ne.setSearchMethod(p.tree);
  ne.setRadiusSearch(s.normal_radius_mm * kM);
  ne.compute(all);
  // Points without a normal (too few neighbours) dropped:
  // pcl::removeNaNNormalsFromPointCloud, pcl::copyPointCloud.
  pcl::Indices keep;
  pcl::removeNaNNormalsFromPointCloud(all, *p.normals, keep);
  pcl::copyPointCloud(*grid, keep, *p.cloud);
  p.tree->setInputCloud(p.cloud);
  return p;
}

// The online part of a method: preprocessed scene -> hypotheses.
class Method {
 public:
  virtual ~Method() = default;
  virtual std::vector<Hyp> hypothesize(const Prepared& scene) const = 0;
};

// What offline training leaves: the preprocessed views (view camera frame),
// their poses T_view_model (metres), the same clouds in the model frame (ICP
// sources, inlier counting) and the method.
struct Model {
  std::vector<Prepared> views;
  std::vector<Mat4> T_view_model;
  std::vector<Cloud::Ptr> view_model;
  std::unique_ptr<Method> method;
};

// ---- Local: FPFH, SHOT ----------------------------------------------------
template <class Desc>
struct LocalCloud {
  Cloud::Ptr kp{new Cloud};
  typename pcl::PointCloud<Desc>::Ptr desc{new pcl::PointCloud<Desc>};
  pcl::PointCloud<pcl::ReferenceFrame>::Ptr rf{new pcl::PointCloud<pcl::ReferenceFrame>};
};

template <class Desc>
constexpr bool kIsShot = std::is_same_v<Desc, pcl::SHOT352>;

template <class Desc>
LocalCloud<Desc> describe_local(const Prepared& p, const pb::LocalSettings& s) {
  LocalCloud<Desc> out;
  // Keypoints: pcl::UniformSampling (per keypoint voxel, the point nearest its centre).
  pcl::UniformSampling<Point> us;
  us.setInputCloud(p.cloud);
  us.setRadiusSearch(s.keypoint_voxel_mm * kM);
  us.filter(*out.kp);
  // Descriptors at the keypoints, the whole cloud as search surface:
  // pcl::SHOTEstimation or pcl::FPFHEstimation (single-threaded classes).
  std::conditional_t<kIsShot<Desc>, pcl::SHOTEstimation<Point, pcl::Normal, Desc>,
                     pcl::FPFHEstimation<Point, pcl::Normal, Desc>> est;
  est.setInputCloud(out.kp);
  est.setInputNormals(p.normals);
  est.setSearchSurface(p.cloud);
  est.setSearchMethod(p.tree);
  est.setRadiusSearch(s.descriptor_radius_mm * kM);
  est.compute(*out.desc);
  // Local reference frames for Hough voting: pcl::BOARDLocalReferenceFrameEstimation.
  pcl::BOARDLocalReferenceFrameEstimation<Point, pcl::Normal, pcl::ReferenceFrame> board;
  board.setFindHoles(true);
  board.setRadiusSearch(s.lrf_radius_mm * kM);
  board.setInputCloud(out.kp);
  board.setInputNormals(p.normals);
  board.setSearchSurface(p.cloud);
  board.setSearchMethod(p.tree);
  board.compute(*out.rf);
  return out;
}

template <class Desc>
class LocalMethod : public Method {
 public:
  LocalMethod(const Model& m, const pb::LocalSettings& s) : s_(s), T_view_model_(m.T_view_model) {
    for (size_t v = 0; v < m.views.size(); ++v) {
      views_.push_back(describe_local<Desc>(m.views[v], s));
      for (size_t k = 0; k < views_.back().desc->size(); ++k) {
        all_->push_back((*views_.back().desc)[k]);
        owner_.emplace_back(int(v), int(k));
      }
    }
    match_.setInputCloud(all_);  // the model descriptors of every view
  }

  std::vector<Hyp> hypothesize(const Prepared& scene) const override {
    const LocalCloud<Desc> sc = describe_local<Desc>(scene, s_);
    // Matching: pcl::KdTreeFLANN over the model descriptors, the nearest one
    // (k = 1) per scene keypoint, kept under the squared-distance threshold;
    // correspondences split by the training view they point into.
    const float thr = float(kIsShot<Desc> ? s_.match_threshold : s_.fpfh_match_threshold);
    std::vector<pcl::CorrespondencesPtr> corrs;
    for (size_t v = 0; v < views_.size(); ++v) corrs.emplace_back(new pcl::Correspondences);
    pcl::Indices idx(1);
    std::vector<float> d2(1);
    for (size_t i = 0; i < sc.desc->size(); ++i) {
      const Desc& d = (*sc.desc)[i];
      float first;
      if constexpr (kIsShot<Desc>) first = d.descriptor[0]; else first = d.histogram[0];
      if (!std::isfinite(first)) continue;
      if (match_.nearestKSearch(d, 1, idx, d2) == 1 && d2[0] < thr) {
        const auto [v, k] = owner_[size_t(idx[0])];
        corrs[size_t(v)]->emplace_back(k, int(i), d2[0]);
      }
    }
    // Grouping, per training view: pcl::Hough3DGrouping (BOARD frames vote
    // for the model's reference point; its RANSAC gives each cluster's pose).
    std::vector<Hyp> out;
    for (size_t v = 0; v < views_.size(); ++v) {
      if (double(corrs[v]->size()) < s_.hough_min_votes) continue;  // cannot reach the threshold
      pcl::Hough3DGrouping<Point, Point, pcl::ReferenceFrame, pcl::ReferenceFrame> hough;
      hough.setHoughBinSize(s_.hough_bin_mm * kM);
      hough.setHoughThreshold(s_.hough_min_votes);
      hough.setUseInterpolation(s_.hough_interpolation);
      hough.setUseDistanceWeight(false);
      hough.setInputCloud(views_[v].kp);
      hough.setInputRf(views_[v].rf);
      hough.setSceneCloud(sc.kp);
      hough.setSceneRf(sc.rf);
      hough.setModelSceneCorrespondences(corrs[v]);
      std::vector<Mat4, Eigen::aligned_allocator<Mat4>> rototranslations;
      std::vector<pcl::Correspondences> clustered;
      hough.recognize(rototranslations, clustered);
      for (size_t k = 0; k < rototranslations.size() && k < clustered.size(); ++k)
        out.push_back({rototranslations[k] * T_view_model_[v], int(v), double(clustered[k].size())});
    }
    std::stable_sort(out.begin(), out.end(), [](const Hyp& a, const Hyp& b) { return a.score > b.score; });
    if (out.size() > size_t(s_.max_hypotheses)) out.resize(size_t(s_.max_hypotheses));
    return out;
  }

 private:
  pb::LocalSettings s_;
  std::vector<Mat4> T_view_model_;
  std::vector<LocalCloud<Desc>> views_;
  typename pcl::PointCloud<Desc>::Ptr all_{new pcl::PointCloud<Desc>};
  std::vector<std::pair<int, int>> owner_;  // row of all_ -> (view, keypoint)
  pcl::KdTreeFLANN<Desc> match_;
};

// ---- Global: CVFH, OUR-CVFH, ESF ------------------------------------------
enum class GlobalKind { kCvfh, kOurCvfh, kEsf };

template <class Sig>
struct GlobalSig {
  Sig hist;
  Eigen::Vector3f centroid = Eigen::Vector3f::Zero();  // of the described region
  bool has_rf = false;
  Mat4 T_rf_cam = Mat4::Identity();  // OUR-CVFH: camera -> its reference frame
  int cloud = 0;                     // training view or scene cluster
};

// The signatures of one cloud (a training view or a scene cluster).
template <class Sig>
std::vector<GlobalSig<Sig>> describe_global(GlobalKind kind, const Cloud::Ptr& c, const Normals::Ptr& n,
                                            const pb::GlobalSettings& g, int cloud) {
  std::vector<GlobalSig<Sig>> out;
  pcl::PointCloud<Sig> sigs;
  if constexpr (std::is_same_v<Sig, pcl::ESFSignature640>) {
    // pcl::ESFEstimation: one signature of the whole cloud; pcl::compute3DCentroid.
    pcl::ESFEstimation<Point, Sig> esf;
    esf.setInputCloud(c);
    esf.compute(sigs);
    Eigen::Vector4f centroid;
    pcl::compute3DCentroid(*c, centroid);
    for (const Sig& s : sigs) out.push_back({s, centroid.head<3>(), false, Mat4::Identity(), cloud});
  } else {
    std::vector<Eigen::Vector3f, Eigen::aligned_allocator<Eigen::Vector3f>> centroids;
    std::vector<Mat4, Eigen::aligned_allocator<Mat4>> frames;
    std::vector<bool> valid;
    auto run = [&](auto& est) {  // the settings CVFH and OUR-CVFH share
      est.setInputCloud(c);
      est.setInputNormals(n);
      est.setSearchMethod(Tree::Ptr(new Tree));
      est.setEPSAngleThreshold(float(g.cvfh_eps_angle_deg * M_PI / 180.0));
      est.setCurvatureThreshold(float(g.cvfh_curvature_threshold));
      est.setClusterTolerance(float(g.cvfh_cluster_tolerance_mm * kM));
      est.setRadiusNormals(float(g.cvfh_normal_radius_mm * kM));
      est.setMinPoints(size_t(g.cvfh_min_region_points));
      est.setNormalizeBins(g.cvfh_normalize_bins);
      est.compute(sigs);
      est.getCentroidClusters(centroids);
    };
    if (kind == GlobalKind::kCvfh) {
      // pcl::CVFHEstimation: one signature per stable region (one VFH of the
      // whole cloud if none), with the region's centroid.
      pcl::CVFHEstimation<Point, pcl::Normal, Sig> est;
      run(est);
    } else {
      // pcl::OURCVFHEstimation: one signature per semi-global unique
      // reference frame (the frames give the whole pose).
      pcl::OURCVFHEstimation<Point, pcl::Normal, Sig> est;
      est.setAxisRatio(float(g.ourcvfh_axis_ratio));
      est.setMinAxisValue(float(g.ourcvfh_min_axis_value));
      est.setRefineClusters(float(g.ourcvfh_refine_clusters));
      run(est);
      est.getTransforms(frames);
      est.getValidTransformsVec(valid);
    }
    for (size_t k = 0; k < sigs.size(); ++k) {
      GlobalSig<Sig> s{sigs[k], Eigen::Vector3f::Zero(), false, Mat4::Identity(), cloud};
      if (kind == GlobalKind::kOurCvfh) {  // a signature without a valid frame gives no pose
        if (k >= frames.size() || k >= valid.size() || !valid[k]) continue;
        s.has_rf = true;
        s.T_rf_cam = frames[k];
      } else {
        if (k >= centroids.size()) continue;
        s.centroid = centroids[k];
      }
      out.push_back(s);
    }
  }
  return out;
}

// Camera roll histogram about the ray to `centroid`: pcl::CRHEstimation.
inline Crh roll_histogram(const Cloud::Ptr& c, const Normals::Ptr& n, const Eigen::Vector3f& centroid) {
  pcl::CRHEstimation<Point, pcl::Normal, pcl::Histogram<90>> est;
  est.setInputCloud(c);
  est.setInputNormals(n);
  Eigen::Vector4f c4(centroid.x(), centroid.y(), centroid.z(), 1.f);
  est.setCentroid(c4);
  Crh out;
  est.compute(out);
  return out;
}

template <class Sig>
class GlobalMethod : public Method {
 public:
  GlobalMethod(GlobalKind kind, const Model& m, const pb::GlobalSettings& g) : kind_(kind), g_(g), m_(m) {
    for (size_t v = 0; v < m.views.size(); ++v)
      for (auto& s : describe_global<Sig>(kind, m.views[v].cloud, m.views[v].normals, g, int(v))) {
        crh_.push_back(s.has_rf ? Crh() : roll_histogram(m.views[v].cloud, m.views[v].normals, s.centroid));
        hists_->push_back(s.hist);
        sigs_.push_back(s);
      }
    // Every bin compared: PCL's generic DefaultPointRepresentation (used for
    // ESFSignature640, which has no specialization) reads the first 3 floats only.
    match_.setPointRepresentation(pcl::make_shared<const pcl::DefaultFeatureRepresentation<Sig>>());
    match_.setInputCloud(hists_);
  }

  std::vector<Hyp> hypothesize(const Prepared& scene) const override {
    // Segmentation: pcl::EuclideanClusterExtraction on the scene's kd-tree;
    // each cluster copied out (pcl::copyPointCloud) and described.
    std::vector<pcl::PointIndices> clusters;
    pcl::EuclideanClusterExtraction<Point> ec;
    ec.setClusterTolerance(g_.cluster_tolerance_mm * kM);
    ec.setMinClusterSize(g_.cluster_min_points);
    ec.setMaxClusterSize(g_.cluster_max_points);
    ec.setSearchMethod(scene.tree);
    ec.setInputCloud(scene.cloud);
    ec.extract(clusters);
    std::vector<Prepared> parts(clusters.size());
    std::vector<GlobalSig<Sig>> ssigs;
    for (size_t c = 0; c < clusters.size(); ++c) {
      pcl::copyPointCloud(*scene.cloud, clusters[c], *parts[c].cloud);
      pcl::copyPointCloud(*scene.normals, clusters[c], *parts[c].normals);
      for (auto& s : describe_global<Sig>(kind_, parts[c].cloud, parts[c].normals, g_, int(c))) ssigs.push_back(s);
    }
    // Matching: pcl::KdTreeFLANN over the model signatures, the top_k nearest
    // of each scene signature; the top_k pairs overall.
    struct Pair {
      float d2;
      int model, scene;
    };
    std::vector<Pair> pairs;
    const int k = std::min<int>(g_.top_k, int(sigs_.size()));
    pcl::Indices idx;
    std::vector<float> d2;
    for (size_t i = 0; i < ssigs.size() && k > 0; ++i)
      for (int j = 0, n = match_.nearestKSearch(ssigs[i].hist, k, idx, d2); j < n; ++j)
        pairs.push_back({d2[size_t(j)], int(idx[size_t(j)]), int(i)});
    std::stable_sort(pairs.begin(), pairs.end(), [](const Pair& a, const Pair& b) { return a.d2 < b.d2; });
    if (pairs.size() > size_t(g_.top_k)) pairs.resize(size_t(g_.top_k));
    // Pose per pair: OUR-CVFH from the two reference frames; otherwise the
    // roll about the centroid ray by pcl::CRHAlignment (scene CRH against
    // the view's), as PCL's CRH-based global recognizer does.
    std::vector<Hyp> out;
    for (const Pair& p : pairs) {
      const GlobalSig<Sig>& ms = sigs_[size_t(p.model)];
      const GlobalSig<Sig>& ss = ssigs[size_t(p.scene)];
      const double score = 1.0 / (1.0 + std::sqrt(p.d2));
      if (ms.has_rf && ss.has_rf) {
        out.push_back({Mat4(ss.T_rf_cam.inverse() * ms.T_rf_cam) * m_.T_view_model[size_t(ms.cloud)], ms.cloud, score});
        continue;
      }
      Cloud::Ptr scene_part = parts[size_t(ss.cloud)].cloud, view = m_.views[size_t(ms.cloud)].cloud;
      Crh scene_crh = roll_histogram(scene_part, parts[size_t(ss.cloud)].normals, ss.centroid);
      Crh view_crh = crh_[size_t(p.model)];
      Eigen::Vector3f cs = ss.centroid, cv = ms.centroid;
      pcl::CRHAlignment<Point, 90> align;
      align.setInputAndTargetView(scene_part, view);
      align.setInputAndTargetCentroids(cs, cv);
      align.align(scene_crh, view_crh);
      std::vector<Mat4, Eigen::aligned_allocator<Mat4>> rolls;
      align.getTransforms(rolls);
      // Its transforms map the input (scene) onto the target (view): inverted.
      for (const Mat4& R : rolls) out.push_back({Mat4(R.inverse()) * m_.T_view_model[size_t(ms.cloud)], ms.cloud, score});
    }
    return out;
  }

 private:
  GlobalKind kind_;
  pb::GlobalSettings g_;
  const Model& m_;
  std::vector<GlobalSig<Sig>> sigs_;
  std::vector<Crh> crh_;  // per model signature (empty when it has a frame)
  typename pcl::PointCloud<Sig>::Ptr hists_{new pcl::PointCloud<Sig>};
  pcl::KdTreeFLANN<Sig> match_;
};

}  // namespace stock
