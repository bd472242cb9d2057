// The local pipeline as a Method (thesis 3.1): keypoints by a
// second voxel grid, FPFH or SHOT descriptors, nearest-descriptor matching
// against the descriptors of every training view, 3D Hough voting per
// training view with BOARD reference frames, a Procrustes (SVD) pose per
// cluster. PCL-free: the building blocks are in the other files of this
// folder (internal.h lists them).
#include <Eigen/Geometry>
#ifdef _OPENMP
#include <omp.h>
#endif
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <optional>
#include <stdexcept>
#include <string>

#include "recognition/local/local.h"
#include "recognition/local/internal.h"
#include "recognition/method.h"
#include "recognition/stages.h"

namespace pb {


int local::omp_threads(int threads) {
#ifdef _OPENMP
  return threads > 0 ? threads : omp_get_max_threads();  // OMP_NUM_THREADS, as run gives its workers
#else
  return 1;
#endif
}

namespace {

using namespace local;

enum class Kind : uint32_t { Fpfh = 1, Shot = 2 };

int dim_of(Kind k) { return k == Kind::Fpfh ? kFpfhDim : kShotDim; }

// Described keypoints of one cloud: only those with a valid descriptor AND a
// valid reference frame (others can neither match nor vote). A training
// view keeps all three; the scene's voting keypoints (the matched ones with
// a valid frame) leave `desc` empty.
struct Described {
  std::vector<Vec3f> kp;
  std::vector<float> desc;  // kp.size() x dim
  std::vector<float> lrf;   // kp.size() x 9
};

std::vector<float> descriptors(Kind kind, const PointSet& cloud, const std::vector<int>& idx,
                               const LocalSettings& s) {
  return kind == Kind::Fpfh ? compute_fpfh(cloud, idx, s.descriptor_radius_mm, s.threads, s.max_support_points)
                            : compute_shot(cloud, idx, s.descriptor_radius_mm, s.threads, s.max_support_points);
}

// The cloud FPFH, SHOT and the BOARD frames take their neighbours from, with
// the keypoints' indices in it: the cloud itself, or the keypoints alone
// (LocalSettings::support_from_keypoints). Either way keypoint i is the
// cloud's point idx[i]. Safe to copy: no pointer into itself.
struct Support {
  const PointSet* whole = nullptr;  // the cloud, when it is the support
  PointSet own;                     // else the keypoints alone
  std::vector<int> at;              // keypoint i is support point at[i]
  const PointSet& cloud() const { return whole ? *whole : own; }
};

Support support_of(const PointSet& cloud, const std::vector<int>& idx, const LocalSettings& s) {
  Support sp;
  if (!s.support_from_keypoints) {
    sp.whole = &cloud;
    sp.at = idx;
    return sp;
  }
  sp.own = subset(cloud, idx);
  sp.at.resize(idx.size());
  for (size_t i = 0; i < idx.size(); ++i) sp.at[i] = static_cast<int>(i);
  return sp;
}

Described keep_valid(const PointSet& cloud, const std::vector<int>& idx, const std::vector<float>& desc,
                     const std::vector<float>& lrf, int dim) {
  Described d;
  for (size_t i = 0; i < idx.size(); ++i) {
    const float* dr = desc.data() + i * dim;
    const float* lr = lrf.data() + i * kLrfDim;
    if (!finite_row(dr, dim) || !finite_row(lr, kLrfDim)) continue;
    d.kp.push_back(cloud.points[idx[i]]);
    d.desc.insert(d.desc.end(), dr, dr + dim);
    d.lrf.insert(d.lrf.end(), lr, lr + kLrfDim);
  }
  return d;
}

// The scene's described keypoints (the describe stage).
struct SceneKeypoints {
  std::vector<int> idx;        // keypoints: indices into the scene
  Support sp;                  // their support cloud
  std::vector<float> desc;     // idx.size() x dim
  std::vector<int> described;  // positions in idx of the keypoints with a valid descriptor
};

// Per described keypoint, its matches: (index row, squared distance).
using Neighbours = std::vector<std::vector<std::pair<int, float>>>;

// One Hough cluster of one training view.
struct Cand {
  int view;
  HoughCluster cluster;
};

// The group stage's result: the voting keypoints (no descriptors) and the
// clusters, in view order.
struct Clusters {
  Described voters;
  std::vector<Cand> cands;
};

constexpr char kMagic[8] = {'P', 'B', 'L', 'O', 'C', 'A', 'L', '1'};

class LocalMethod : public Method {
 public:
  LocalMethod(Kind kind, const LocalSettings& s) : kind_(kind), s_(s) {}

  std::string name() const override { return kind_ == Kind::Fpfh ? "fpfh" : "shot"; }

  void train(const std::vector<ViewData>& views, uint64_t /*seed: no random choice*/) override {
    const LocalSettings& s = s_;
    views_.clear();
    for (const ViewData& v : views) {
      const std::vector<int> idx = voxel_keypoints(v.cloud, s.keypoint_voxel_mm);
      const Support sp = support_of(v.cloud, idx, s);
      const std::vector<float> desc = descriptors(kind_, sp.cloud(), sp.at, s);
      const std::vector<float> lrf = compute_board_lrf(sp.cloud(), sp.at, s.lrf_radius_mm);
      views_.push_back(keep_valid(v.cloud, idx, desc, lrf, dim_of(kind_)));
    }
    build_index();
  }

  void save(BinaryWriter& out) const override {
    out.raw(kMagic, sizeof(kMagic));
    out.pod<uint32_t>(static_cast<uint32_t>(kind_));
    out.pod<uint32_t>(static_cast<uint32_t>(dim_of(kind_)));
    out.pod<uint64_t>(views_.size());
    for (const Described& d : views_) {
      out.points(d.kp);
      out.vec(d.desc);
      out.vec(d.lrf);
    }
  }

  void load(BinaryReader& in) override {
    in.expect(kMagic, sizeof(kMagic), "local method state");
    if (in.pod<uint32_t>() != static_cast<uint32_t>(kind_)) in.fail("stored for another descriptor");
    const int dim = static_cast<int>(in.pod<uint32_t>());
    if (dim != dim_of(kind_)) in.fail("descriptor size mismatch");
    const uint64_t nv = in.pod<uint64_t>();
    if (nv > 100000) in.fail("corrupt view count");
    std::vector<Described> views(nv);
    for (Described& d : views) {
      d.kp = in.points();
      d.desc = in.vec<float>();
      d.lrf = in.vec<float>();
      const size_t n = d.kp.size();
      if (d.desc.size() != n * dim || d.lrf.size() != n * kLrfDim) in.fail("inconsistent array sizes");
    }
    views_ = std::move(views);
    build_index();
  }

  std::vector<Hypothesis> hypothesize(const PointSet& scene, const std::vector<ViewData>& views,
                                      // No random choice here: the only one, PCL's RANSAC
                                      // inside Hough3DGrouping, uses its fixed seed.
                                      uint64_t seed, StageTimes& times) const override {
    return run_stages(*this, SceneInput{scene, views, seed}, times);
  }

  // The stages (stages.h), in order.

  // Describe: keypoints and their descriptors; only keypoints with a valid
  // descriptor are matched.
  std::optional<SceneKeypoints> describe(const SceneInput& in) const {
    if (in.views.size() != views_.size())
      throw std::invalid_argument("local method: " + std::to_string(in.views.size()) +
                                  " views given, trained on " + std::to_string(views_.size()));
    if (in.scene.empty() || !in.scene.has_normals() || index_.size() == 0) return std::nullopt;
    const int dim = dim_of(kind_);
    SceneKeypoints d;
    d.idx = voxel_keypoints(in.scene, s_.keypoint_voxel_mm);
    d.sp = support_of(in.scene, d.idx, s_);
    d.desc = descriptors(kind_, d.sp.cloud(), d.sp.at, s_);
    for (size_t i = 0; i < d.idx.size(); ++i)
      if (finite_row(d.desc.data() + i * dim, dim)) d.described.push_back(static_cast<int>(i));
    return d;
  }

  // Match: each described keypoint's k nearest model descriptors under the
  // threshold, over every view.
  Neighbours match(const SceneInput&, const SceneKeypoints& d) const {
    const int dim = dim_of(kind_);
    const float thr = static_cast<float>(kind_ == Kind::Fpfh ? s_.fpfh_match_threshold : s_.match_threshold);
    const std::vector<float> compacted = described_rows(d, dim);
    const float* query = compacted.empty() ? d.desc.data() : compacted.data();
    // One result slot per described keypoint, merged in keypoint order: the
    // same matches for any thread count. Blocks of kMatchBlock queries: each
    // indexed row is read once per block.
    constexpr int kMatchBlock = 32;
    Neighbours nn(d.described.size());
    const int nkp = static_cast<int>(d.described.size());
    const int nblocks = (nkp + kMatchBlock - 1) / kMatchBlock;
#pragma omp parallel for schedule(dynamic, 1) num_threads(omp_threads(s_.threads)) if (nblocks > 1)
    for (int b = 0; b < nblocks; ++b) {
      const int first = b * kMatchBlock, count = std::min(kMatchBlock, nkp - first);
      index_.knn_block(query + static_cast<size_t>(first) * dim, count, s_.matches_per_keypoint, thr,
                       nn.data() + first, kind_ == Kind::Shot ? s_.match_max_checks : 0);
    }
    return nn;
  }

  // Group: the matched keypoints' reference frames, then 3D Hough voting
  // per training view.
  Clusters group(const SceneInput& in, const SceneKeypoints& d, Neighbours nn) const {
    Clusters g;
    const std::vector<std::vector<Match>> per_view = voting_keypoints(in, d, nn, g.voters);
    HoughParams hp;
    hp.bin_mm = s_.hough_bin_mm;
    hp.min_votes = s_.hough_min_votes;
    hp.interpolation = s_.hough_interpolation;
    for (size_t v = 0; v < views_.size(); ++v) {
      if (static_cast<int>(per_view[v].size()) < s_.hough_min_votes) continue;
      for (HoughCluster& c : hough_grouping(views_[v].kp, views_[v].lrf, g.voters.kp, g.voters.lrf, per_view[v], hp))
        g.cands.push_back({static_cast<int>(v), std::move(c)});
    }
    return g;
  }

  // Initial pose: Procrustes on each cluster's correspondences; ranked by
  // votes, ties in view / cluster order (stable, deterministic).
  std::vector<Hypothesis> initial_pose(const SceneInput& in, const SceneKeypoints&, Clusters g) const {
    std::vector<Hypothesis> out;
    for (const Cand& c : g.cands) {
      if (c.cluster.matches.size() < 3) continue;
      std::vector<Vec3f> m, q;
      for (const Match& k : c.cluster.matches) {
        m.push_back(views_[c.view].kp[k.model]);
        q.push_back(g.voters.kp[k.scene]);
      }
      Pose T_scene_view;
      if (!procrustes(m, q, T_scene_view)) continue;
      Hypothesis h;
      h.T_cam_model = T_scene_view * in.views[c.view].T_cam_model;
      h.view = c.view;
      h.score = static_cast<double>(c.cluster.matches.size());
      out.push_back(h);
    }
    std::stable_sort(out.begin(), out.end(),
                     [](const Hypothesis& a, const Hypothesis& b) { return a.score > b.score; });
    if (static_cast<int>(out.size()) > s_.max_hypotheses) out.resize(s_.max_hypotheses);
    return out;
  }

 private:
  // The described keypoints' descriptor rows: empty when every keypoint is
  // described (the usual case: the rows are d.desc as it is), else a
  // compacted copy.
  static std::vector<float> described_rows(const SceneKeypoints& d, int dim) {
    std::vector<float> compacted;
    if (d.described.size() < d.idx.size()) {
      compacted.resize(d.described.size() * static_cast<size_t>(dim));
      for (size_t i = 0; i < d.described.size(); ++i)
        std::copy_n(d.desc.data() + static_cast<size_t>(d.described[i]) * dim, dim, compacted.data() + i * dim);
    }
    return compacted;
  }

  // The voting keypoints: the matched ones with a valid reference frame
  // (frames are computed for the matched keypoints alone, each on its own,
  // so they are those of describing every keypoint's frame first). Returns
  // their matches per training view.
  std::vector<std::vector<Match>> voting_keypoints(const SceneInput& in, const SceneKeypoints& d,
                                                   const Neighbours& nn, Described& voters) const {
    std::vector<int> matched;  // support point indices
    for (size_t i = 0; i < nn.size(); ++i)
      if (!nn[i].empty()) matched.push_back(d.sp.at[static_cast<size_t>(d.described[i])]);
    const std::vector<float> lrf = compute_board_lrf(d.sp.cloud(), matched, s_.lrf_radius_mm);
    std::vector<std::vector<Match>> per_view(views_.size());
    for (size_t i = 0, m = 0; i < nn.size(); ++i) {
      if (nn[i].empty()) continue;
      const float* lr = lrf.data() + (m++) * kLrfDim;
      if (!finite_row(lr, kLrfDim)) continue;
      const int slot = static_cast<int>(voters.kp.size());
      voters.kp.push_back(in.scene.points[static_cast<size_t>(d.idx[static_cast<size_t>(d.described[i])])]);
      voters.lrf.insert(voters.lrf.end(), lr, lr + kLrfDim);
      for (const auto& [row, d2] : nn[i]) {
        const auto& [v, k] = row_owner_[row];
        per_view[v].push_back({k, slot, d2});
      }
    }
    return per_view;
  }

  void build_index() {
    std::vector<float> all;
    row_owner_.clear();
    for (size_t v = 0; v < views_.size(); ++v) {
      all.insert(all.end(), views_[v].desc.begin(), views_[v].desc.end());
      for (size_t k = 0; k < views_[v].kp.size(); ++k)
        row_owner_.emplace_back(static_cast<int>(v), static_cast<int>(k));
    }
    index_.build(all, dim_of(kind_));
  }

  Kind kind_;
  LocalSettings s_;
  std::vector<Described> views_;
  std::vector<std::pair<int, int>> row_owner_;  // index row -> (view, keypoint)
  DescriptorIndex index_;
};

}  // namespace

namespace local {

bool procrustes(const std::vector<Vec3f>& model, const std::vector<Vec3f>& scene, Pose& T_scene_model) {
  const size_t n = model.size();
  if (n < 3 || scene.size() != n) return false;
  Eigen::Matrix3Xd src(3, n), dst(3, n);
  for (size_t i = 0; i < n; ++i) {
    src.col(static_cast<Eigen::Index>(i)) = model[i].cast<double>();
    dst.col(static_cast<Eigen::Index>(i)) = scene[i].cast<double>();
  }
  // Degenerate (collinear or coincident) model points give no rotation.
  const Eigen::Matrix3Xd centered = src.colwise() - src.rowwise().mean();
  const Eigen::Vector3d sv = Eigen::JacobiSVD<Eigen::Matrix3d>(centered * centered.transpose()).singularValues();
  if (!(sv[1] > 1e-9 * std::max(1.0, sv[0])) || !(sv[1] > 1e-6)) return false;
  const Eigen::Matrix4d T = Eigen::umeyama(src, dst, false);
  if (!T.allFinite()) return false;
  T_scene_model = Pose::from_matrix(T);
  return true;
}

}  // namespace local

std::unique_ptr<Method> make_fpfh_method(const LocalSettings& s) { return std::make_unique<LocalMethod>(Kind::Fpfh, s); }
std::unique_ptr<Method> make_shot_method(const LocalSettings& s) { return std::make_unique<LocalMethod>(Kind::Shot, s); }

}  // namespace pb
