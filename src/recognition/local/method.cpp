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
#include <stdexcept>
#include <string>

#include "core/timer.h"
#include "recognition/local/local.h"
#include "recognition/local/internal.h"
#include "recognition/method.h"

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
                                      uint64_t /*seed*/, StageTimes& times) const override {
    const LocalSettings& s = s_;
    std::vector<Hypothesis> out;
    if (views.size() != views_.size())
      throw std::invalid_argument("local method: " + std::to_string(views.size()) +
                                  " views given, trained on " + std::to_string(views_.size()));
    if (scene.empty() || !scene.has_normals() || index_.size() == 0) return out;
    const int dim = dim_of(kind_);

    // Describe: keypoints + descriptors; only keypoints with a valid
    // descriptor are matched.
    Timer timer;
    const std::vector<int> idx = voxel_keypoints(scene, s.keypoint_voxel_mm);
    const Support sp = support_of(scene, idx, s);
    const std::vector<float> desc = descriptors(kind_, sp.cloud(), sp.at, s);
    std::vector<int> described;  // positions in idx
    for (size_t i = 0; i < idx.size(); ++i)
      if (finite_row(desc.data() + i * dim, dim)) described.push_back(static_cast<int>(i));
    times.describe += timer.seconds();

    // Match: k nearest model descriptors under the threshold, per view.
    timer.reset();
    const float thr = static_cast<float>(kind_ == Kind::Fpfh ? s.fpfh_match_threshold : s.match_threshold);
    // The described keypoints' rows: the descriptors as they are when every
    // one is valid (the usual case), else a compacted copy.
    std::vector<float> compacted;
    if (described.size() < idx.size()) {
      compacted.resize(described.size() * static_cast<size_t>(dim));
      for (size_t i = 0; i < described.size(); ++i)
        std::copy_n(desc.data() + static_cast<size_t>(described[i]) * dim, dim, compacted.data() + i * dim);
    }
    const float* query = compacted.empty() ? desc.data() : compacted.data();
    // One result slot per described keypoint, merged in keypoint order: the
    // same matches for any thread count.
    // Blocks of kMatchBlock queries: each indexed row is read once per block.
    constexpr int kMatchBlock = 32;
    std::vector<std::vector<std::pair<int, float>>> nn(described.size());
    const int nkp = static_cast<int>(described.size());
    const int nblocks = (nkp + kMatchBlock - 1) / kMatchBlock;
#pragma omp parallel for schedule(dynamic, 1) num_threads(omp_threads(s.threads)) if (nblocks > 1)
    for (int b = 0; b < nblocks; ++b) {
      const int first = b * kMatchBlock, count = std::min(kMatchBlock, nkp - first);
      index_.knn_block(query + static_cast<size_t>(first) * dim, count, s.matches_per_keypoint, thr,
                       nn.data() + first, kind_ == Kind::Shot ? s.match_max_checks : 0);
    }
    times.match += timer.seconds();

    // Scene reference frames, needed for voting (part of grouping): only of
    // the matched keypoints, the only ones that vote; a match whose keypoint
    // has no valid frame is dropped. Each keypoint is matched on its own, so
    // the matches are those of describing every keypoint's frame first.
    timer.reset();
    std::vector<int> matched;  // support point indices
    for (size_t i = 0; i < nn.size(); ++i)
      if (!nn[i].empty()) matched.push_back(sp.at[static_cast<size_t>(described[i])]);
    const std::vector<float> lrf = compute_board_lrf(sp.cloud(), matched, s.lrf_radius_mm);
    Described sc;  // the voting keypoints (no descriptors)
    std::vector<std::vector<Match>> per_view(views_.size());
    for (size_t i = 0, m = 0; i < nn.size(); ++i) {
      if (nn[i].empty()) continue;
      const float* lr = lrf.data() + (m++) * kLrfDim;
      if (!finite_row(lr, kLrfDim)) continue;
      const int slot = static_cast<int>(sc.kp.size());
      sc.kp.push_back(scene.points[static_cast<size_t>(idx[static_cast<size_t>(described[i])])]);
      sc.lrf.insert(sc.lrf.end(), lr, lr + kLrfDim);
      for (const auto& [row, d2] : nn[i]) {
        const auto& [v, k] = row_owner_[row];
        per_view[v].push_back({k, slot, d2});
      }
    }
    times.group += timer.seconds();

    // Group: 3D Hough voting per training view.
    timer.reset();
    HoughParams hp;
    hp.bin_mm = s.hough_bin_mm;
    hp.min_votes = s.hough_min_votes;
    hp.interpolation = s.hough_interpolation;
    struct Cand {
      int view;
      HoughCluster cluster;
    };
    std::vector<Cand> cands;
    for (size_t v = 0; v < views_.size(); ++v) {
      if (static_cast<int>(per_view[v].size()) < s.hough_min_votes) continue;
      for (HoughCluster& c : hough_grouping(views_[v].kp, views_[v].lrf, sc.kp, sc.lrf, per_view[v], hp))
        cands.push_back({static_cast<int>(v), std::move(c)});
    }
    times.group += timer.seconds();

    // Initial pose: Procrustes on each cluster's correspondences.
    timer.reset();
    for (const Cand& c : cands) {
      if (c.cluster.matches.size() < 3) continue;
      std::vector<Vec3f> m, q;
      for (const Match& k : c.cluster.matches) {
        m.push_back(views_[c.view].kp[k.model]);
        q.push_back(sc.kp[k.scene]);
      }
      Pose T_scene_view;
      if (!procrustes(m, q, T_scene_view)) continue;
      Hypothesis h;
      h.T_cam_model = T_scene_view * views[c.view].T_cam_model;
      h.view = c.view;
      h.score = static_cast<double>(c.cluster.matches.size());
      out.push_back(h);
    }
    // Rank by votes; ties keep view / cluster order (stable, deterministic).
    std::stable_sort(out.begin(), out.end(),
                     [](const Hypothesis& a, const Hypothesis& b) { return a.score > b.score; });
    if (static_cast<int>(out.size()) > s.max_hypotheses) out.resize(s.max_hypotheses);
    times.initial_pose += timer.seconds();
    return out;
  }

 private:
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
