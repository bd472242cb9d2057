// PPF (Drost, Ulrich, Navab and Ilic 2010, "Model globally, match locally")
// as a descriptor Method, on PCL's point pair features.
//
// Training: every training view is mapped into the model frame and merged;
// the merged cloud is voxel-downsampled to about PpfSettings::model_points
// points (the pair table is O(N^2)); pcl::PPFEstimation computes the feature
// (f1..f4) and the angle alpha_m of every ordered model pair, and the
// discretized features (PCL's discretization: floor(f / step)) go into a
// table sorted by feature key. pcl::PPFHashMapSearch is not used: its hash
// (XOR of the four small bin indices, shifted by 0..3 bits) puts the whole
// table into a few hundred buckets, so building it is quadratic in the pair
// count (measured, wall time on a busy 2-core machine: 0.8 s for 300 model
// points, 70 s for 600, while PPFEstimation itself took 0.1 s and 0.4 s) and
// every lookup scans a long bucket. Pairs whose feature is undefined (NaN: the (i, i) pairs,
// coincident points) are left out, so they never vote.
//
// Matching follows the paper with PCL's conventions (the same feature,
// alpha and pose formulas as pcl::PPFRegistration): each scene reference
// point (a seeded random subset, scene_reference_fraction of the scene) is
// paired with every scene point within the model's diameter; each model pair
// in the same feature bin votes for (model reference point, alpha) in an
// accumulator; the best cell gives one pose per reference point. The poses
// are clustered greedily, most votes first (a pose joins the first cluster
// whose leading pose is within position_cluster_mm and rotation_cluster_deg);
// a cluster's pose is the mean translation and the sign-aligned mean
// quaternion of its members, its score the sum of their votes. The best
// max_hypotheses clusters are the hypotheses.
//
// pcl::PPFRegistration itself is not called: it returns only its best
// cluster (the pipeline refines and verifies several), takes every k-th scene
// point in input order as a reference, pairs only points within half the
// model diameter, averages quaternions without aligning their signs, and
// prints INFO lines on stdout.
//
// Hypothesis::view is the training view whose viewing direction (model
// frame) is closest to the camera direction implied by the hypothesis, so
// the pipeline refines and verifies with the model view that sees the same
// side of the object.
//
// Units: millimetres throughout (PCL's PPF code is unit-free apart from the
// distance step, which is a fraction of the model diameter).
#include <pcl/features/pfh_tools.h>
#include <pcl/features/ppf.h>
#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <istream>
#include <limits>
#include <map>
#include <numeric>
#include <ostream>
#include <stdexcept>
#include <tuple>

#include "core/random.h"
#include "core/timer.h"
#include "recognition/method.h"
#include "recognition/pipeline.h"

namespace pb {

namespace {

constexpr char kStateMagic[8] = {'P', 'B', 'P', 'P', 'F', '0', '0', '1'};

// One model pair in the feature table.
struct PairEntry {
  uint64_t key;
  uint32_t ref, other;  // model reference point, second point
  bool operator<(const PairEntry& o) const {
    return std::tie(key, ref, other) < std::tie(o.key, o.ref, o.other);
  }
};

// The discretized feature (PCL's floor(f / step), in float) packed into 64
// bits, 16 per component (bin indices are clamped to +-32767).
uint64_t feature_key(float f1, float f2, float f3, float f4, float angle_step, float distance_step) {
  auto bin = [](float f, float step) {
    const float b = std::floor(f / step);
    const float c = std::max(-32767.f, std::min(32767.f, b));
    return static_cast<uint64_t>(static_cast<int64_t>(c) + 32768) & 0xffffu;
  };
  return (bin(f1, angle_step) << 48) | (bin(f2, angle_step) << 32) | (bin(f3, angle_step) << 16) |
         bin(f4, distance_step);
}

struct Cloud {
  std::vector<Vec3f> points, normals;
};

// Voxel grid on points with normals: mean point and renormalized mean normal
// per cell (cells whose normals cancel out are dropped). Deterministic order
// (cells sorted by their integer coordinates).
Cloud voxel_grid(const Cloud& in, double leaf) {
  struct Acc {
    Eigen::Vector3d p = Eigen::Vector3d::Zero(), n = Eigen::Vector3d::Zero();
    int count = 0;
  };
  std::map<std::tuple<int64_t, int64_t, int64_t>, Acc> cells;
  for (size_t i = 0; i < in.points.size(); ++i) {
    const Vec3f& p = in.points[i];
    const auto key = std::make_tuple(static_cast<int64_t>(std::floor(p.x() / leaf)),
                                     static_cast<int64_t>(std::floor(p.y() / leaf)),
                                     static_cast<int64_t>(std::floor(p.z() / leaf)));
    Acc& a = cells[key];
    a.p += p.cast<double>();
    a.n += in.normals[i].cast<double>();
    ++a.count;
  }
  Cloud out;
  for (const auto& kv : cells) {
    const Acc& a = kv.second;
    if (!(a.n.norm() > 1e-6 * a.count)) continue;
    out.points.push_back((a.p / a.count).cast<float>());
    out.normals.push_back(a.n.normalized().cast<float>());
  }
  return out;
}

// The voxel grid whose size gives at most `target` points, as close as a
// bisection on the leaf size gets (the count falls as the leaf grows).
Cloud downsample_to(const Cloud& in, int target) {
  if (in.points.size() <= static_cast<size_t>(target)) return voxel_grid(in, 1e-3);
  Eigen::AlignedBox3f box;
  for (const auto& p : in.points) box.extend(p);
  double lo = 1e-3, hi = std::max(1e-2, static_cast<double>(box.diagonal().norm()));
  Cloud best = voxel_grid(in, hi);
  for (int it = 0; it < 30; ++it) {
    const double mid = 0.5 * (lo + hi);
    Cloud c = voxel_grid(in, mid);
    if (c.points.size() <= static_cast<size_t>(target)) {
      hi = mid;
      best = std::move(c);
    } else {
      lo = mid;
    }
  }
  return best;
}

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

template <typename T>
void put(std::ostream& out, const T& v) {
  out.write(reinterpret_cast<const char*>(&v), sizeof(T));
}
template <typename T>
T get(std::istream& in) {
  T v{};
  in.read(reinterpret_cast<char*>(&v), sizeof(T));
  if (!in) throw std::runtime_error("ppf: truncated trained state");
  return v;
}

struct PoseVote {
  Pose pose;
  double votes = 0;
};

class PpfMethod : public Method {
 public:
  std::string name() const override { return "ppf"; }

  void train(const std::vector<ViewData>& views, const RecognitionSettings& s) override {
    Cloud merged;
    for (const auto& v : views) {
      if (!v.cloud.has_normals()) continue;
      const Pose T_model_cam = v.T_cam_model.inverse();
      for (size_t i = 0; i < v.cloud.size(); ++i) {
        merged.points.push_back((T_model_cam * v.cloud.points[i].cast<double>()).cast<float>());
        merged.normals.push_back((T_model_cam.R * v.cloud.normals[i].cast<double>()).cast<float>());
      }
    }
    model_ = downsample_to(merged, s.ppf.model_points);
    angle_step_ = static_cast<float>(s.ppf.angle_step_deg * M_PI / 180.0);
    diameter_ = 0;
    for (size_t i = 0; i < model_.points.size(); ++i)
      for (size_t j = i + 1; j < model_.points.size(); ++j)
        diameter_ = std::max(diameter_, (model_.points[i] - model_.points[j]).norm());
    distance_step_ = static_cast<float>(s.ppf.distance_step_fraction) * diameter_;
    features_.clear();
    if (model_.points.size() >= 3 && diameter_ > 0) compute_features();
    build_search();
  }

  void save(std::ostream& out) const override {
    out.write(kStateMagic, sizeof kStateMagic);
    put(out, angle_step_);
    put(out, distance_step_);
    put(out, diameter_);
    put<uint64_t>(out, model_.points.size());
    for (size_t i = 0; i < model_.points.size(); ++i)
      for (int k = 0; k < 3; ++k) {
        put(out, model_.points[i][k]);
        put(out, model_.normals[i][k]);
      }
    put<uint64_t>(out, features_.size());
    for (const auto& f : features_) {
      put(out, f.f1);
      put(out, f.f2);
      put(out, f.f3);
      put(out, f.f4);
      put(out, f.alpha_m);
    }
  }

  void load(std::istream& in) override {
    char magic[sizeof kStateMagic];
    in.read(magic, sizeof magic);
    if (!in || std::memcmp(magic, kStateMagic, sizeof magic) != 0)
      throw std::runtime_error("ppf: not a PPF trained state");
    angle_step_ = get<float>(in);
    distance_step_ = get<float>(in);
    diameter_ = get<float>(in);
    const uint64_t n = get<uint64_t>(in);
    if (n > 100000) throw std::runtime_error("ppf: bad model point count");
    model_.points.assign(n, Vec3f::Zero());
    model_.normals.assign(n, Vec3f::Zero());
    for (size_t i = 0; i < n; ++i)
      for (int k = 0; k < 3; ++k) {
        model_.points[i][k] = get<float>(in);
        model_.normals[i][k] = get<float>(in);
      }
    const uint64_t nf = get<uint64_t>(in);
    if (nf != (n >= 3 ? n * n : 0)) throw std::runtime_error("ppf: feature count does not match the model");
    features_.resize(nf);
    for (auto& f : features_) {
      f.f1 = get<float>(in);
      f.f2 = get<float>(in);
      f.f3 = get<float>(in);
      f.f4 = get<float>(in);
      f.alpha_m = get<float>(in);
    }
    if (!(angle_step_ > 0) || (nf > 0 && !(distance_step_ > 0))) throw std::runtime_error("ppf: bad steps");
    build_search();
  }

  std::vector<Hypothesis> hypothesize(const PointSet& scene, const std::vector<ViewData>& views,
                                      const RecognitionSettings& s, uint64_t seed,
                                      StageTimes& times) const override {
    std::vector<Hypothesis> out;
    if (table_.empty() || !scene.has_normals() || scene.size() < 2) return out;

    // Describe: the scene as a PCL cloud with a kd-tree; the seeded subset of
    // reference points.
    Timer timer;
    pcl::PointCloud<pcl::PointNormal>::Ptr cloud(new pcl::PointCloud<pcl::PointNormal>);
    cloud->resize(scene.size());
    for (size_t i = 0; i < scene.size(); ++i) {
      (*cloud)[i].getVector3fMap() = scene.points[i];
      (*cloud)[i].getNormalVector3fMap() = scene.normals[i];
      (*cloud)[i].data_n[3] = 0.f;
      (*cloud)[i].curvature = 0.f;
    }
    pcl::KdTreeFLANN<pcl::PointNormal> tree;
    tree.setInputCloud(cloud);
    std::vector<int> refs(scene.size());
    std::iota(refs.begin(), refs.end(), 0);
    const size_t n_refs = std::max<size_t>(
        1, static_cast<size_t>(std::lround(s.ppf.scene_reference_fraction * static_cast<double>(scene.size()))));
    if (n_refs < refs.size()) {
      Rng rng(seed);
      for (size_t i = 0; i < n_refs; ++i) {
        const size_t j = i + static_cast<size_t>(rng.uniform_int(0, static_cast<int>(refs.size() - i - 1)));
        std::swap(refs[i], refs[j]);
      }
      refs.resize(n_refs);
      std::sort(refs.begin(), refs.end());
    }
    times.describe += timer.seconds();

    // Match: vote per reference point.
    timer.reset();
    const size_t n_model = model_.points.size();
    const int n_alpha = std::max(1, static_cast<int>(std::floor(2 * M_PI / angle_step_)));
    std::vector<uint32_t> acc(n_model * static_cast<size_t>(n_alpha), 0);
    std::vector<PoseVote> poses;
    pcl::Indices nn;
    std::vector<float> d2;
    for (int r : refs) {
      const Vec3f sr = scene.points[r], nr = scene.normals[r];
      if (!sr.allFinite() || !nr.allFinite()) continue;
      const Eigen::Affine3f T_sg = to_reference_frame(sr, nr);
      tree.radiusSearch((*cloud)[r], diameter_, nn, d2);
      std::fill(acc.begin(), acc.end(), 0u);
      for (int i : nn) {
        if (i == r) continue;
        float f1, f2, f3, f4;
        if (!pcl::computePairFeatures((*cloud)[r].getVector4fMap(), (*cloud)[r].getNormalVector4fMap(),
                                      (*cloud)[i].getVector4fMap(), (*cloud)[i].getNormalVector4fMap(), f1, f2,
                                      f3, f4))
          continue;
        if (!std::isfinite(f1) || !std::isfinite(f2) || !std::isfinite(f3) || !std::isfinite(f4)) continue;
        const PairEntry probe{feature_key(f1, f2, f3, f4, angle_step_, distance_step_), 0, 0};
        auto it = std::lower_bound(table_.begin(), table_.end(), probe);
        if (it == table_.end() || it->key != probe.key) continue;
        const float alpha_s = pcl_alpha(T_sg, scene.points[i]);
        for (; it != table_.end() && it->key == probe.key; ++it) {
          float alpha = features_[static_cast<size_t>(it->ref) * n_model + it->other].alpha_m - alpha_s;
          if (!std::isfinite(alpha)) continue;
          if (alpha < -M_PI) alpha += static_cast<float>(2 * M_PI);
          else if (alpha > M_PI) alpha -= static_cast<float>(2 * M_PI);
          int bin = static_cast<int>(std::floor((alpha + M_PI) / angle_step_));
          bin = std::max(0, std::min(n_alpha - 1, bin));
          ++acc[it->ref * static_cast<size_t>(n_alpha) + static_cast<size_t>(bin)];
        }
      }
      const auto best = std::max_element(acc.begin(), acc.end());  // first maximum: deterministic
      if (*best == 0) continue;
      const size_t cell = static_cast<size_t>(best - acc.begin());
      const size_t mr = cell / static_cast<size_t>(n_alpha);
      const int bin = static_cast<int>(cell % static_cast<size_t>(n_alpha));
      const float alpha = static_cast<float>((bin + 0.5) * angle_step_ - M_PI);
      const Eigen::Affine3f T_mg = to_reference_frame(model_.points[mr], model_.normals[mr]);
      const Eigen::Affine3f T = T_sg.inverse() * Eigen::AngleAxisf(alpha, Vec3f::UnitX()) * T_mg;
      PoseVote pv;
      pv.pose.R = T.linear().cast<double>();
      pv.pose.t = T.translation().cast<double>();
      pv.votes = *best;
      poses.push_back(pv);
    }
    times.match += timer.seconds();

    // Group: greedy pose clustering, most votes first.
    timer.reset();
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
    const double max_angle = s.ppf.rotation_cluster_deg * M_PI / 180.0;
    for (size_t k = 0; k < poses.size(); ++k) {
      const PoseVote& pv = poses[k];
      const Eigen::Quaterniond q(pv.pose.R);
      Cluster* home = nullptr;
      for (auto& c : clusters) {
        if ((pv.pose.t - c.lead.t).norm() >= s.ppf.position_cluster_mm) continue;
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
    if (clusters.size() > static_cast<size_t>(s.ppf.max_hypotheses))
      clusters.resize(static_cast<size_t>(s.ppf.max_hypotheses));
    for (const auto& c : clusters) {
      Hypothesis h;
      h.T_cam_model.t = c.t_sum / c.members;
      Eigen::Quaterniond q;
      q.coeffs() = c.q_sum.normalized();
      h.T_cam_model.R = q.toRotationMatrix();
      h.score = c.votes;
      out.push_back(h);
    }
    times.group += timer.seconds();

    // Initial pose: the training view that sees the object from the
    // hypothesis' direction.
    timer.reset();
    for (auto& h : out) {
      const Vec3 cam_dir = -(h.T_cam_model.R.transpose() * h.T_cam_model.t);
      double best = -std::numeric_limits<double>::infinity();
      for (size_t v = 0; v < views.size(); ++v) {
        const Vec3 view_dir = -(views[v].T_cam_model.R.transpose() * views[v].T_cam_model.t);
        const double c = cam_dir.normalized().dot(view_dir.normalized());
        if (c > best) {
          best = c;
          h.view = static_cast<int>(v);
        }
      }
    }
    times.initial_pose += timer.seconds();
    return out;
  }

 private:
  void compute_features() {
    pcl::PointCloud<pcl::PointNormal>::Ptr cloud(new pcl::PointCloud<pcl::PointNormal>);
    cloud->resize(model_.points.size());
    for (size_t i = 0; i < model_.points.size(); ++i) {
      (*cloud)[i].getVector3fMap() = model_.points[i];
      (*cloud)[i].getNormalVector3fMap() = model_.normals[i];
      (*cloud)[i].data_n[3] = 0.f;
      (*cloud)[i].curvature = 0.f;
    }
    pcl::PointCloud<pcl::PPFSignature> f;
    pcl::PPFEstimation<pcl::PointNormal, pcl::PointNormal, pcl::PPFSignature> est;
    est.setInputCloud(cloud);
    est.setInputNormals(cloud);
    est.compute(f);
    features_.assign(f.begin(), f.end());
  }

  // The feature table: every model pair with a defined feature, sorted by
  // key (then by pair, so equal keys come in a fixed order).
  void build_search() {
    table_.clear();
    const size_t n = model_.points.size();
    if (n < 3 || features_.size() != n * n) return;
    table_.reserve(features_.size());
    for (size_t i = 0; i < n; ++i)
      for (size_t j = 0; j < n; ++j) {
        const auto& f = features_[i * n + j];
        if (i == j || !std::isfinite(f.f1) || !std::isfinite(f.f2) || !std::isfinite(f.f3) ||
            !std::isfinite(f.f4) || !std::isfinite(f.alpha_m))
          continue;
        table_.push_back({feature_key(f.f1, f.f2, f.f3, f.f4, angle_step_, distance_step_),
                          static_cast<uint32_t>(i), static_cast<uint32_t>(j)});
      }
    std::sort(table_.begin(), table_.end());
  }

  Cloud model_;                                   // downsampled merged views, model frame (mm)
  std::vector<pcl::PPFSignature> features_;       // n x n pair features (row = reference point)
  std::vector<PairEntry> table_;                  // model pairs sorted by feature key (empty: nothing to match)
  float angle_step_ = 0, distance_step_ = 0, diameter_ = 0;
};

}  // namespace

std::unique_ptr<Method> make_ppf_method() { return std::make_unique<PpfMethod>(); }

}  // namespace pb
