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
// alpha and pose formulas as pcl::PPFRegistration): the scene is
// voxel-downsampled to the model's sampling (scene_sampling_steps distance
// steps, as Drost et al. sample scene and model alike); each scene reference
// point (a seeded random subset, scene_reference_fraction of those points)
// is paired with every such scene point within the model's diameter, found
// on the project's kd-tree; the model pairs of the same feature key come
// from a hash index over the sorted table, alpha_m stored with each pair; each model pair
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
#include <pcl/features/ppf.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "core/log.h"
#include "core/random.h"
#include "recognition/method.h"
#include "recognition/stages.h"
#include "recognition/pcl_adapter.h"
#include "recognition/ppf/internal.h"
#include "recognition/preprocess/voxel_grid.h"

namespace pb {

namespace {

// The scene as the PPF stages see it (the describe stage).
struct PpfScene {
  bool whole_scene = false;  // the scene is paired as it is (no sampling step)
  PointSet sampled;          // else: the scene at the model's sampling
  std::vector<int> refs;     // reference points: indices into the paired cloud
  PointSet partners;         // a coarser sampling the references pair with (empty: the paired cloud)
  const PointSet& paired(const SceneInput& in) const { return whole_scene ? in.scene : sampled; }
};

constexpr char kStateMagic[8] = {'P', 'B', 'P', 'P', 'F', '0', '0', '2'};

class PpfMethod : public Method {
 public:
  std::string name() const override { return "ppf"; }

  explicit PpfMethod(const PpfSettings& s) : s_(s) {}

  void train(const std::vector<ViewData>& views, uint64_t /*seed: no random choice*/) override {
    PointSet merged;
    for (const auto& v : views) {
      if (!v.cloud.has_normals()) continue;
      const Pose T_model_cam = v.T_cam_model.inverse();
      for (size_t i = 0; i < v.cloud.size(); ++i) {
        merged.points.push_back((T_model_cam * v.cloud.points[i].cast<double>()).cast<float>());
        merged.normals.push_back((T_model_cam.R * v.cloud.normals[i].cast<double>()).cast<float>());
      }
    }
    const PointSet model = sample_model(merged);
    m_ = ppf::Model();
    m_.points = model.points;
    m_.normals = model.normals;
    m_.angle_step = static_cast<float>(s_.angle_step_deg * M_PI / 180.0);
    m_.diameter = max_distance(m_.points);
    m_.distance_step = static_cast<float>(s_.distance_step_fraction) * m_.diameter;
    if (m_.points.size() >= 3 && m_.diameter > 0) compute_features();
    build_search();
    log_event(LogLevel::debug, "ppf_model",
              {{"points", m_.points.size()}, {"pairs", m_.table.size()}, {"diameter_mm", m_.diameter}});
  }

  void save(BinaryWriter& out) const override {
    out.raw(kStateMagic, sizeof kStateMagic);
    out.pod(m_.angle_step);
    out.pod(m_.distance_step);
    out.pod(m_.diameter);
    out.points(m_.points);
    out.points(m_.normals);
    out.vec(m_.features);
  }

  void load(BinaryReader& in) override {
    in.expect(kStateMagic, sizeof kStateMagic, "PPF trained state");
    ppf::Model m;
    m.angle_step = in.pod<float>();
    m.distance_step = in.pod<float>();
    m.diameter = in.pod<float>();
    m.points = in.points();
    m.normals = in.points();
    m.features = in.vec<ppf::PairFeature>();
    const size_t n = m.points.size();
    if (n > 100000 || m.normals.size() != n) in.fail("bad model point count");
    if (m.features.size() != (n >= 3 ? n * n : 0)) in.fail("feature count does not match the model");
    if (!(m.angle_step > 0) || (!m.features.empty() && !(m.distance_step > 0))) in.fail("bad steps");
    m_ = std::move(m);
    build_search();
  }

  std::vector<Hypothesis> hypothesize(const PointSet& scene, const std::vector<ViewData>& views, uint64_t seed,
                                      StageTimes& times) const override {
    return run_stages(*this, SceneInput{scene, views, seed}, times);
  }

  // The stages (stages.h), in order.

  // Describe: the scene at the model's sampling, the seeded subset of
  // reference points, and the partners (a coarser sampling where asked).
  std::optional<PpfScene> describe(const SceneInput& in) const {
    if (m_.table.empty() || !in.scene.has_normals() || in.scene.size() < 2) return std::nullopt;
    PpfScene d;
    const double leaf = s_.scene_sampling_steps * m_.distance_step;
    VoxelGridOptions grid;
    grid.leaf_mm = leaf;
    grid.normal_cluster_deg = s_.normal_cluster_deg;
    d.whole_scene = !(leaf > 0);
    if (!d.whole_scene) d.sampled = voxel_downsample(in.scene, grid);
    const PointSet& paired = d.paired(in);
    if (paired.size() < 2 || !paired.has_normals()) return std::nullopt;
    d.refs = ppf::reference_points(paired.size(), s_.scene_reference_fraction, in.seed);
    const double partner_leaf = s_.scene_partner_steps * m_.distance_step;
    if (partner_leaf > 0 && partner_leaf != leaf) {
      VoxelGridOptions coarse = grid;
      coarse.leaf_mm = partner_leaf;
      d.partners = voxel_downsample(in.scene, coarse);
    }
    return d;
  }

  // Match: the votes of each reference point's pairs, its best pose.
  std::vector<ppf::PoseVote> match(const SceneInput& in, const PpfScene& d) const {
    ppf::VoteOptions vo;
    vo.margin = static_cast<float>(s_.neighbour_margin);
    vo.vote_once = s_.vote_once;
    return ppf::vote(m_, d.paired(in), d.refs, vo, d.partners.points.empty() ? nullptr : &d.partners);
  }

  // Group: greedy pose clustering, most votes first.
  std::vector<Hypothesis> group(const SceneInput&, const PpfScene&, std::vector<ppf::PoseVote> poses) const {
    return ppf::cluster_poses(std::move(poses), s_);
  }

  // Initial pose: each hypothesis gets the training view that sees the
  // object from its direction.
  std::vector<Hypothesis> initial_pose(const SceneInput& in, const PpfScene&, std::vector<Hypothesis> out) const {
    for (auto& h : out) {
      const Vec3 cam_dir = -(h.T_cam_model.R.transpose() * h.T_cam_model.t);
      double best = -std::numeric_limits<double>::infinity();
      for (size_t v = 0; v < in.views.size(); ++v) {
        const Vec3 view_dir = -(in.views[v].T_cam_model.R.transpose() * in.views[v].T_cam_model.t);
        const double c = cam_dir.normalized().dot(view_dir.normalized());
        if (c > best) {
          best = c;
          h.view = static_cast<int>(v);
        }
      }
    }
    return out;
  }

 private:
  static float max_distance(const std::vector<Vec3f>& pts) {
    float d = 0;
    for (size_t i = 0; i < pts.size(); ++i)
      for (size_t j = i + 1; j < pts.size(); ++j) d = std::max(d, (pts[i] - pts[j]).norm());
    return d;
  }

  // The model's points: the merged views voxel-sampled at
  // model_sampling_steps distance steps of the diameter (estimated on a
  // 1000-point grid, within a cell of the true one), a voxel's points split by
  // normal; coarsened to at most model_points. With model_sampling_steps 0:
  // the grid that leaves about model_points.
  PointSet sample_model(const PointSet& merged) const {
    VoxelGridOptions grid;  // the PPF model's grid: cells by x, p / leaf, cancelled normals dropped
    grid.order = VoxelGridOptions::Order::kXYZ;
    grid.cell_index = VoxelGridOptions::CellIndex::kDivide;
    grid.drop_cancelled_normals = 1e-6;
    grid.normal_cluster_deg = s_.normal_cluster_deg;
    if (s_.model_sampling_steps > 0 && !merged.points.empty()) {
      VoxelGridOptions coarse = grid;
      coarse.normal_cluster_deg = 0;
      const double d = max_distance(voxel_downsample_to(merged, 1000, coarse).points);
      grid.leaf_mm = s_.model_sampling_steps * s_.distance_step_fraction * d;
      if (grid.leaf_mm > 0) {
        PointSet model = voxel_downsample(merged, grid);
        if (model.size() <= static_cast<size_t>(s_.model_points)) return model;
      }
    }
    return voxel_downsample_to(merged, s_.model_points, grid);
  }

  void compute_features() {
    const auto cloud = pcl_adapter::point_normals(m_.points, m_.normals);
    pcl::PointCloud<pcl::PPFSignature> f;
    pcl::PPFEstimation<pcl::PointNormal, pcl::PointNormal, pcl::PPFSignature> est;
    est.setInputCloud(cloud);
    est.setInputNormals(cloud);
    est.compute(f);
    m_.features.resize(f.size());
    for (size_t i = 0; i < f.size(); ++i) m_.features[i] = {f[i].f1, f[i].f2, f[i].f3, f[i].f4, f[i].alpha_m};
  }

  void build_search() { ppf::build_table(m_); }

  PpfSettings s_;
  ppf::Model m_;
};

}  // namespace

std::unique_ptr<Method> make_ppf_method(const PpfSettings& s) { return std::make_unique<PpfMethod>(s); }

}  // namespace pb
