// The local pipeline as a Method (THESIS.md "Local pipeline"): keypoints by a
// second voxel grid, FPFH or SHOT descriptors, kd-tree matching against the
// descriptors of every training view, 3D Hough voting per training view with
// BOARD reference frames, a Procrustes (SVD) pose per cluster. PCL-free: the
// PCL parts live in local_{fpfh,shot,match,hough}.cpp.
#include <Eigen/Geometry>
#ifdef _OPENMP
#include <omp.h>
#endif
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <istream>
#include <ostream>
#include <stdexcept>
#include <string>

#include "core/timer.h"
#include "recognition/local/local.h"
#include "recognition/local/internal.h"
#include "recognition/method.h"
#include "recognition/pipeline.h"

namespace pb {

// ---------------------------------------------------------------------------
// Settings

void parse_local(const YamlNode& node, LocalSettings& s) {
  if (!node.defined()) return;
  node.check_keys({"keypoint_voxel_mm", "descriptor_radius_mm", "lrf_radius_mm", "match_threshold",
                   "fpfh_match_threshold", "matches_per_keypoint", "hough_bin_mm", "hough_min_votes",
                   "hough_interpolation", "max_hypotheses", "threads"});
  s.keypoint_voxel_mm = node.get_positive("keypoint_voxel_mm", s.keypoint_voxel_mm);
  s.descriptor_radius_mm = node.get_positive("descriptor_radius_mm", s.descriptor_radius_mm);
  s.lrf_radius_mm = node.get_positive("lrf_radius_mm", s.lrf_radius_mm);
  s.match_threshold = node.get_positive("match_threshold", s.match_threshold);
  s.fpfh_match_threshold = node.get_positive("fpfh_match_threshold", s.fpfh_match_threshold);
  s.hough_bin_mm = node.get_positive("hough_bin_mm", s.hough_bin_mm);
  node.read("hough_interpolation", s.hough_interpolation);
  auto read_int = [&](const char* key, int& v, int lo) {
    if (!node.has(key)) return;
    const int x = node.get<int>(key);
    if (x < lo) node[key].fail("must be >= " + std::to_string(lo));
    v = x;
  };
  read_int("matches_per_keypoint", s.matches_per_keypoint, 1);
  read_int("hough_min_votes", s.hough_min_votes, 1);
  read_int("max_hypotheses", s.max_hypotheses, 1);
  read_int("threads", s.threads, 0);
}

namespace {

using namespace local;

int omp_threads(int threads) {
#ifdef _OPENMP
  return threads > 0 ? threads : omp_get_num_procs();
#else
  return 1;
#endif
}

enum class Kind : uint32_t { Fpfh = 1, Shot = 2 };

int dim_of(Kind k) { return k == Kind::Fpfh ? kFpfhDim : kShotDim; }

// Described keypoints of one cloud: only those with a valid descriptor AND a
// valid reference frame (others can neither match nor vote).
struct Described {
  std::vector<Vec3f> kp;
  std::vector<float> desc;  // kp.size() x dim
  std::vector<float> lrf;   // kp.size() x 9
};

std::vector<float> descriptors(Kind kind, const PointSet& cloud, const std::vector<int>& idx,
                               const LocalSettings& s) {
  return kind == Kind::Fpfh ? compute_fpfh(cloud, idx, s.descriptor_radius_mm, s.threads)
                            : compute_shot(cloud, idx, s.descriptor_radius_mm, s.threads);
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

// Binary helpers (host byte order: the cache is machine-local).
template <typename T>
void put(std::ostream& out, const T& v) {
  out.write(reinterpret_cast<const char*>(&v), sizeof(T));
}
template <typename T>
void put_vec(std::ostream& out, const std::vector<T>& v) {
  const uint64_t n = v.size();
  put(out, n);
  if (n) out.write(reinterpret_cast<const char*>(v.data()), static_cast<std::streamsize>(n * sizeof(T)));
}
template <typename T>
T get(std::istream& in) {
  T v{};
  in.read(reinterpret_cast<char*>(&v), sizeof(T));
  if (!in) throw std::runtime_error("local method cache: truncated stream");
  return v;
}
template <typename T>
std::vector<T> get_vec(std::istream& in, uint64_t max_n) {
  const uint64_t n = get<uint64_t>(in);
  if (n > max_n) throw std::runtime_error("local method cache: corrupt array size");
  std::vector<T> v(n);
  if (n) in.read(reinterpret_cast<char*>(v.data()), static_cast<std::streamsize>(n * sizeof(T)));
  if (!in) throw std::runtime_error("local method cache: truncated stream");
  return v;
}

constexpr char kMagic[8] = {'P', 'B', 'L', 'O', 'C', 'A', 'L', '1'};

class LocalMethod : public Method {
 public:
  explicit LocalMethod(Kind kind) : kind_(kind) {}

  std::string name() const override { return kind_ == Kind::Fpfh ? "fpfh" : "shot"; }

  void train(const std::vector<ViewData>& views, const RecognitionSettings& rs) override {
    const LocalSettings& s = rs.local;
    views_.clear();
    for (const ViewData& v : views) {
      const std::vector<int> idx = voxel_keypoints(v.cloud, s.keypoint_voxel_mm);
      const std::vector<float> desc = descriptors(kind_, v.cloud, idx, s);
      const std::vector<float> lrf = compute_board_lrf(v.cloud, idx, s.lrf_radius_mm);
      views_.push_back(keep_valid(v.cloud, idx, desc, lrf, dim_of(kind_)));
    }
    build_index();
  }

  void save(std::ostream& out) const override {
    out.write(kMagic, sizeof(kMagic));
    put<uint32_t>(out, static_cast<uint32_t>(kind_));
    put<uint32_t>(out, static_cast<uint32_t>(dim_of(kind_)));
    put<uint64_t>(out, views_.size());
    for (const Described& d : views_) {
      std::vector<float> kp;
      kp.reserve(d.kp.size() * 3);
      for (const Vec3f& p : d.kp) kp.insert(kp.end(), {p.x(), p.y(), p.z()});
      put_vec(out, kp);
      put_vec(out, d.desc);
      put_vec(out, d.lrf);
    }
  }

  void load(std::istream& in) override {
    char magic[sizeof(kMagic)];
    in.read(magic, sizeof(magic));
    if (!in || std::memcmp(magic, kMagic, sizeof(kMagic)) != 0)
      throw std::runtime_error("local method cache: bad magic");
    if (get<uint32_t>(in) != static_cast<uint32_t>(kind_))
      throw std::runtime_error("local method cache: stored for another descriptor");
    const int dim = static_cast<int>(get<uint32_t>(in));
    if (dim != dim_of(kind_)) throw std::runtime_error("local method cache: descriptor size mismatch");
    const uint64_t nv = get<uint64_t>(in);
    if (nv > 100000) throw std::runtime_error("local method cache: corrupt view count");
    constexpr uint64_t kMax = uint64_t(1) << 32;
    std::vector<Described> views(nv);
    for (Described& d : views) {
      const std::vector<float> kp = get_vec<float>(in, kMax);
      d.desc = get_vec<float>(in, kMax);
      d.lrf = get_vec<float>(in, kMax);
      const size_t n = kp.size() / 3;
      if (kp.size() != n * 3 || d.desc.size() != n * dim || d.lrf.size() != n * kLrfDim)
        throw std::runtime_error("local method cache: inconsistent array sizes");
      for (size_t i = 0; i < n; ++i) d.kp.emplace_back(kp[3 * i], kp[3 * i + 1], kp[3 * i + 2]);
    }
    views_ = std::move(views);
    build_index();
  }

  std::vector<Hypothesis> hypothesize(const PointSet& scene, const std::vector<ViewData>& views,
                                      // No random choice here: the only one, PCL's RANSAC
                                      // inside Hough3DGrouping, uses its fixed seed.
                                      const RecognitionSettings& rs, uint64_t /*seed*/,
                                      StageTimes& times) const override {
    const LocalSettings& s = rs.local;
    std::vector<Hypothesis> out;
    if (views.size() != views_.size())
      throw std::invalid_argument("local method: " + std::to_string(views.size()) +
                                  " views given, trained on " + std::to_string(views_.size()));
    if (scene.empty() || !scene.has_normals() || index_.size() == 0) return out;
    const int dim = dim_of(kind_);

    // Describe: keypoints + descriptors.
    Timer timer;
    const std::vector<int> idx = voxel_keypoints(scene, s.keypoint_voxel_mm);
    const std::vector<float> desc = descriptors(kind_, scene, idx, s);
    times.describe += timer.seconds();

    // Scene reference frames (needed for voting): part of grouping.
    timer.reset();
    const std::vector<float> lrf = compute_board_lrf(scene, idx, s.lrf_radius_mm);
    const Described sc = keep_valid(scene, idx, desc, lrf, dim);
    times.group += timer.seconds();

    // Match: k nearest model descriptors under the threshold, per view.
    timer.reset();
    const float thr = static_cast<float>(kind_ == Kind::Fpfh ? s.fpfh_match_threshold : s.match_threshold);
    // One result slot per scene keypoint, merged in keypoint order: the same
    // matches for any thread count.
    // Blocks of kMatchBlock queries: each indexed row is read once per block.
    constexpr int kMatchBlock = 32;
    std::vector<std::vector<std::pair<int, float>>> nn(sc.kp.size());
    const int nkp = static_cast<int>(sc.kp.size());
    const int nblocks = (nkp + kMatchBlock - 1) / kMatchBlock;
#pragma omp parallel for schedule(dynamic, 1) num_threads(omp_threads(s.threads)) if (nblocks > 1)
    for (int b = 0; b < nblocks; ++b) {
      const int first = b * kMatchBlock, count = std::min(kMatchBlock, nkp - first);
      index_.knn_block(sc.desc.data() + static_cast<size_t>(first) * dim, count, s.matches_per_keypoint, thr,
                       nn.data() + first);
    }
    std::vector<std::vector<Match>> per_view(views_.size());
    for (size_t i = 0; i < nn.size(); ++i)
      for (const auto& [row, d2] : nn[i]) {
        const auto& [v, k] = row_owner_[row];
        per_view[v].push_back({k, static_cast<int>(i), d2});
      }
    times.match += timer.seconds();

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

std::unique_ptr<Method> make_fpfh_method() { return std::make_unique<LocalMethod>(Kind::Fpfh); }
std::unique_ptr<Method> make_shot_method() { return std::make_unique<LocalMethod>(Kind::Shot); }

}  // namespace pb
