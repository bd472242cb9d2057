// The global pipeline's methods (cvfh, esf, cesf, ourcvfh): training,
// matching and initial pose. PCL-free; the PCL parts are behind
// internal.h.
//
// Online, per image (thesis 3.2, the global pipeline):
//  1. describe: Euclidean clusters of the preprocessed scene, then the
//     method's signatures per cluster (CVFH / OUR-CVFH / CESF: one per stable
//     region, or, without one, one of the whole cluster; ESF: one per
//     cluster);
//  2. match: L2 distance of every scene signature to every model signature
//     (or, with matches_per_signature k, to its k nearest only); the top_k
//     pairs overall, ordered by distance, then view, then model signature,
//     then scene signature (deterministic);
//  3. initial pose per pair: translation from the centroid difference; two
//     rotational DoF from aligning the axes (the negated mean normals of the
//     regions, or the camera-to-centroid directions), the roll about that
//     axis from the CRH (each distinct peak one hypothesis, up to
//     crh_max_peaks) or, with skip_crh, from the upright assumption;
//     OUR-CVFH: from the two semi-global reference frames instead.
//  Hypothesis: T_cam_model = T_cam_view_aligned * T_view_model, score
//  1 / (1 + histogram distance).
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <tuple>

#include "core/error.h"
#include "core/random.h"
#include "recognition/global/esf.h"
#include "recognition/global/internal.h"
#include "recognition/method.h"
#include "recognition/stages.h"

namespace pb {
namespace global {

Mat3 roll_rotation(const Vec3f& view_axis, const Vec3f& scene_axis, double theta) {
  const Mat3 Rv = rotation_to_z(view_axis.cast<double>());
  const Mat3 Rs = rotation_to_z(scene_axis.cast<double>());
  return Rs.transpose() * Eigen::AngleAxisd(theta, Vec3::UnitZ()).toRotationMatrix() * Rv;
}

double upright_roll(const Vec3f& view_axis, const Vec3f& scene_axis) {
  const Vec3 up(0, -1, 0);
  const Vec3 uv = rotation_to_z(view_axis.cast<double>()) * up;
  const Vec3 us = rotation_to_z(scene_axis.cast<double>()) * up;
  if (std::hypot(uv.x(), uv.y()) < 1e-6 || std::hypot(us.x(), us.y()) < 1e-6) return 0.0;
  return std::atan2(us.y(), us.x()) - std::atan2(uv.y(), uv.x());
}

int esf_triples(const GlobalSettings& s, size_t points) {
  if (!s.esf_samples_from_points) return s.esf_samples;
  return static_cast<int>(std::min<size_t>(points, static_cast<size_t>(std::numeric_limits<int>::max())));
}

}  // namespace global

namespace {

using global::Signature;

enum class Kind { kCvfh, kEsf, kCesf, kOurCvfh };

const char* kind_name(Kind k) {
  switch (k) {
    case Kind::kCvfh: return "cvfh";
    case Kind::kEsf: return "esf";
    case Kind::kCesf: return "cesf";
    case Kind::kOurCvfh: return "ourcvfh";
  }
  return "?";
}

// Seeds of the ESF samples: training views from the settings' seed, scene
// clusters from the call's seed; one stream per cloud and region.
constexpr uint64_t kTrainStream = 0x6C6F62616C545256ull;  // "globalTRV"
constexpr uint64_t kSceneStream = 0x6C6F62616C534345ull;

Vec3f mean_point(const std::vector<Vec3f>& pts) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const auto& p : pts) c += p.cast<double>();
  return pts.empty() ? Vec3f::Zero() : Vec3f((c / static_cast<double>(pts.size())).cast<float>());
}

// The ESF of a whole cloud, from the cloud's first stream (ESF's signature,
// and CESF's with cesf_whole_cluster).
std::vector<float> whole_cloud_esf(const PointSet& cloud, const GlobalSettings& g, uint64_t seed) {
  Rng rng(derive_seed(seed, {0}));
  return compute_esf(cloud.points, rng, global::esf_triples(g, cloud.points.size()));
}

std::vector<Signature> signatures(Kind kind, const PointSet& cloud, const GlobalSettings& g, uint64_t seed);

// The method's signatures of one cloud (a training view or a scene cluster),
// with view_ray_axis the camera-to-centroid ray for an axis taken from a
// mean normal (CVFH, CESF).
std::vector<Signature> describe_cloud(Kind kind, const PointSet& cloud, const GlobalSettings& g, uint64_t seed) {
  std::vector<Signature> out = signatures(kind, cloud, g, seed);
  if (g.view_ray_axis && (kind == Kind::kCvfh || kind == Kind::kCesf))
    for (Signature& s : out)
      if (s.from_normal && s.centroid.norm() > 0) {
        s.axis = s.centroid.normalized();
        s.from_normal = false;
      }
  return out;
}

std::vector<Signature> signatures(Kind kind, const PointSet& cloud, const GlobalSettings& g, uint64_t seed) {
  std::vector<Signature> out;
  switch (kind) {
    case Kind::kCvfh:
      return global::cvfh_signatures(cloud, g);
    case Kind::kOurCvfh:
      return global::ourcvfh_signatures(cloud, g);
    case Kind::kEsf: {
      if (cloud.size() < 3) return out;
      Signature s;
      s.hist = whole_cloud_esf(cloud, g, seed);
      s.centroid = mean_point(cloud.points);
      if (!(s.centroid.norm() > 0)) return out;
      s.axis = s.centroid.normalized();
      if (g.esf_pose_from_normals && cloud.has_normals()) {
        const Vec3f n = mean_point(cloud.normals);  // toward the viewpoint
        if (!(n.norm() > 0)) return out;
        s.axis = -n.normalized();
        s.from_normal = true;
      }
      out.push_back(std::move(s));
      return out;
    }
    case Kind::kCesf: {
      const auto regions = global::stable_regions(cloud, g);
      // No stable region large enough: as CVFH (pcl::CVFHEstimation falls
      // back to the VFH of all the cloud's points), the ESF of the whole
      // cloud, posed like ESF's (centroid, camera-to-centroid axis).
      if (regions.empty()) return signatures(Kind::kEsf, cloud, g, seed);
      // cesf_whole_cluster: one ESF of the whole cloud, shared by every
      // region's signature.
      const std::vector<float> whole = g.cesf_whole_cluster ? whole_cloud_esf(cloud, g, seed) : std::vector<float>{};
      for (size_t r = 0; r < regions.size(); ++r) {
        Rng rng(derive_seed(seed, {r + 1}));
        Signature s;
        s.hist = g.cesf_whole_cluster ? whole : compute_esf(regions[r].points, rng, global::esf_triples(g, regions[r].points.size()));
        s.centroid = regions[r].centroid;
        s.axis = -regions[r].mean_normal;
        s.from_normal = true;
        out.push_back(std::move(s));
      }
      return out;
    }
  }
  return out;
}

double l2(const std::vector<float>& a, const std::vector<float>& b) {
  double s = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    const double d = static_cast<double>(a[i]) - b[i];
    s += d * d;
  }
  return std::sqrt(s);
}

Mat3 nearest_rotation(const Mat3& M) {
  Eigen::JacobiSVD<Mat3> svd(M, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Mat3 U = svd.matrixU();
  const Mat3 V = svd.matrixV();
  if ((U * V.transpose()).determinant() < 0) U.col(2) *= -1;
  return U * V.transpose();
}

// The scene's clusters and their signatures (the describe stage).
struct SceneSignatures {
  std::vector<PointSet> clusters;  // Euclidean clusters of the scene
  std::vector<Signature> sigs;     // their signatures (source = cluster)
};

// A scene signature matched to a model signature.
struct SigMatch {
  double dist;  // L2 distance of the histograms
  int view, model, scene;
};

// Matches by distance, then view, model signature, scene signature.
bool match_order(const SigMatch& a, const SigMatch& b) {
  return std::tie(a.dist, a.view, a.model, a.scene) < std::tie(b.dist, b.view, b.model, b.scene);
}

constexpr char kMagic[8] = {'P', 'B', 'G', 'L', 'O', 'B', 'A', 'L'};
// 3: CESF falls back to the whole cloud's ESF when it has no stable region
// (states of version 2 lack those signatures: retrained).
constexpr uint32_t kVersion = 3;

class GlobalMethod : public Method {
 public:
  GlobalMethod(Kind kind, const GlobalSettings& g) : kind_(kind), g_(g) {}
  std::string name() const override { return kind_name(kind_); }

  void train(const std::vector<ViewData>& views, uint64_t seed) override {
    sigs_.clear();
    view_poses_.clear();
    for (size_t v = 0; v < views.size(); ++v) {
      view_poses_.push_back(views[v].T_cam_model);
      auto sigs = describe_cloud(kind_, views[v].cloud, g_, derive_seed(seed, {kTrainStream, v}));
      for (auto& sig : sigs) {
        sig.source = static_cast<int>(v);
        sig.crh = global::crh_spectrum(views[v].cloud, sig.axis);
        sigs_.push_back(std::move(sig));
      }
    }
  }

  void save(BinaryWriter& out) const override {
    out.raw(kMagic, sizeof(kMagic));
    out.pod<uint32_t>(kVersion);
    out.pod<uint32_t>(static_cast<uint32_t>(kind_));
    out.pod<uint64_t>(view_poses_.size());
    for (const auto& p : view_poses_) out.pose(p);
    out.pod<uint64_t>(sigs_.size());
    for (const auto& s : sigs_) {
      out.pod<int32_t>(s.source);
      out.vec(s.hist);
      out.points({s.centroid, s.axis});
      out.pod<uint8_t>(s.from_normal ? 1 : 0);
      out.pod<uint8_t>(s.has_rf ? 1 : 0);
      out.pose(s.T_rf_cam);
      out.vec(s.crh);
    }
  }

  void load(BinaryReader& in) override {
    in.expect(kMagic, sizeof(kMagic), "global descriptor state");
    if (in.pod<uint32_t>() != kVersion) in.fail("of another version");
    if (in.pod<uint32_t>() != static_cast<uint32_t>(kind_)) in.fail(std::string("not ") + kind_name(kind_));
    const uint64_t nv = in.pod<uint64_t>();
    if (nv > 100000) in.fail("corrupt view count");
    std::vector<Pose> poses(nv);
    for (auto& p : poses) p = in.pose();
    const uint64_t n = in.pod<uint64_t>();
    std::vector<Signature> sigs;
    for (uint64_t i = 0; i < n; ++i) {
      Signature s;
      s.source = in.pod<int32_t>();
      if (s.source < 0 || static_cast<size_t>(s.source) >= poses.size()) in.fail("corrupt view index");
      s.hist = in.vec<float>();
      const std::vector<Vec3f> ca = in.points();
      if (ca.size() != 2) in.fail("corrupt signature");
      s.centroid = ca[0];
      s.axis = ca[1];
      s.from_normal = in.pod<uint8_t>() != 0;
      s.has_rf = in.pod<uint8_t>() != 0;
      s.T_rf_cam = in.pose();
      s.crh = in.vec<float>();
      sigs.push_back(std::move(s));
    }
    view_poses_ = std::move(poses);
    sigs_ = std::move(sigs);
  }

  std::vector<Hypothesis> hypothesize(const PointSet& scene, const std::vector<ViewData>& views,
                                      uint64_t seed, StageTimes& times) const override {
    return run_stages(*this, SceneInput{scene, views, seed}, times);
  }

  // The stages (stages.h), in order; no group stage.

  // Describe: Euclidean clusters of the scene, each cluster's signatures.
  std::optional<SceneSignatures> describe(const SceneInput& in) const {
    SceneSignatures d;
    const auto clusters = global::euclidean_clusters(in.scene.points, g_.cluster_tolerance_mm, g_.cluster_min_points,
                                                     g_.cluster_max_points);
    for (size_t c = 0; c < clusters.size(); ++c) {
      d.clusters.push_back(subset(in.scene, clusters[c]));
      auto sigs = describe_cloud(kind_, d.clusters.back(), g_, derive_seed(in.seed, {kSceneStream, c}));
      for (auto& sig : sigs) {
        sig.source = static_cast<int>(c);
        d.sigs.push_back(std::move(sig));
      }
    }
    return d;
  }

  // Match: every pair (or each scene signature's nearest), the top_k
  // overall.
  std::vector<SigMatch> match(const SceneInput&, const SceneSignatures& d) const {
    std::vector<SigMatch> matches, own;
    const size_t per_sig = static_cast<size_t>(g_.matches_per_signature);
    for (size_t i = 0; i < d.sigs.size(); ++i) {
      own.clear();
      for (size_t j = 0; j < sigs_.size(); ++j) {
        if (sigs_[j].hist.size() != d.sigs[i].hist.size()) continue;
        const double dist = l2(d.sigs[i].hist, sigs_[j].hist);
        if (!std::isfinite(dist)) continue;
        own.push_back({dist, sigs_[j].source, static_cast<int>(j), static_cast<int>(i)});
      }
      if (per_sig > 0 && own.size() > per_sig) {  // this signature's nearest only
        std::partial_sort(own.begin(), own.begin() + static_cast<std::ptrdiff_t>(per_sig), own.end(), match_order);
        own.resize(per_sig);
      }
      matches.insert(matches.end(), own.begin(), own.end());
    }
    const size_t k = std::min(matches.size(), static_cast<size_t>(std::max(g_.top_k, 1)));
    std::partial_sort(matches.begin(), matches.begin() + k, matches.end(), match_order);
    matches.resize(k);
    return matches;
  }

  // Initial pose: the poses of each match, in match order, scored
  // 1 / (1 + histogram distance).
  std::vector<Hypothesis> initial_pose(const SceneInput&, const SceneSignatures& d,
                                       std::vector<SigMatch> matches) const {
    std::vector<Hypothesis> hyps;
    SceneCrh crh(d.sigs.size());
    for (const SigMatch& m : matches) {
      const Signature& ms = sigs_[m.model];
      for (const Pose& T : aligned_views(d, m, crh)) {
        Hypothesis h;
        h.T_cam_model = T * view_poses_[ms.source];
        h.view = ms.source;
        h.score = 1.0 / (1.0 + m.dist);
        hyps.push_back(h);
      }
    }
    const size_t top_k = static_cast<size_t>(std::max(g_.top_k, 1));
    if (g_.top_k_counts_rolls && hyps.size() > top_k) hyps.resize(top_k);  // the first top_k hypotheses
    return hyps;
  }

 private:
  // The scene signatures' CRHs, computed on first use.
  struct SceneCrh {
    explicit SceneCrh(size_t n) : spectrum(n), done(n, 0) {}
    std::vector<std::vector<float>> spectrum;
    std::vector<char> done;
  };

  // T_cam_view of one match: from the two reference frames (OUR-CVFH),
  // else the axes aligned and each roll of the CRH (or the upright one).
  std::vector<Pose> aligned_views(const SceneSignatures& d, const SigMatch& m, SceneCrh& crh) const {
    const Signature& ms = sigs_[m.model];
    const Signature& ss = d.sigs[m.scene];
    std::vector<Pose> T_cam_view;
    if (kind_ == Kind::kOurCvfh && ms.has_rf && ss.has_rf) {
      Pose T = ss.T_rf_cam.inverse() * ms.T_rf_cam;
      T.R = nearest_rotation(T.R);
      T_cam_view.push_back(T);
      return T_cam_view;
    }
    std::vector<double> rolls;
    if (!g_.skip_crh) {
      if (!crh.done[m.scene]) {
        crh.spectrum[m.scene] = global::crh_spectrum(d.clusters[ss.source], ss.axis);
        crh.done[m.scene] = 1;
      }
      rolls = global::crh_roll_peaks(crh.spectrum[m.scene], ms.crh, g_);
    }
    if (rolls.empty()) rolls.push_back(global::upright_roll(ms.axis, ss.axis));
    for (double theta : rolls) {
      Pose T;
      T.R = global::roll_rotation(ms.axis, ss.axis, theta);
      T.t = ss.centroid.cast<double>() - T.R * ms.centroid.cast<double>();
      T_cam_view.push_back(T);
    }
    return T_cam_view;
  }

  Kind kind_;
  GlobalSettings g_;
  std::vector<Signature> sigs_;   // every training view's signatures (source = view)
  std::vector<Pose> view_poses_;  // T_view_model of each training view
};

}  // namespace

std::unique_ptr<Method> make_cvfh_method(const GlobalSettings& g) { return std::make_unique<GlobalMethod>(Kind::kCvfh, g); }
std::unique_ptr<Method> make_esf_method(const GlobalSettings& g) { return std::make_unique<GlobalMethod>(Kind::kEsf, g); }
std::unique_ptr<Method> make_cesf_method(const GlobalSettings& g) { return std::make_unique<GlobalMethod>(Kind::kCesf, g); }
std::unique_ptr<Method> make_ourcvfh_method(const GlobalSettings& g) { return std::make_unique<GlobalMethod>(Kind::kOurCvfh, g); }

}  // namespace pb
