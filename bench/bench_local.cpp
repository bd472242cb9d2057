// The local pipeline's stages on one generated table image (synthetic
// sensor, the LS5 among distractors, no occluder; the same image as
// bench_global): keypoints, FPFH and SHOT at the scene keypoints, BOARD
// frames, descriptor matching, 3D Hough grouping, and per method (fpfh, shot)
// training and the whole online computation with its stage times as counters
// (preprocess, describe, match, group, initial pose, ICP refinement of every
// hypothesis, inlier count), to set beside the thesis's Table 4.1 times.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <memory>

#include "core/random.h"
#include "core/timer.h"
#include "core/yaml.h"
#include "recognition/local/internal.h"
#include "recognition/method.h"
#include "recognition/pipeline.h"
#include "recognition/preprocess/preprocess.h"
#include "recognition/refine/refine.h"
#include "recognition/registry.h"
#include "recognition/verify/verify.h"
#include "scenes/generator.h"
#include "scenes/views.h"
#include "pcl_reference.h"  // PCL's implementation, the reference

namespace {

using namespace pb;

// Keypoints, descriptors and frames of one cloud (valid rows only).
struct Described {
  std::vector<Vec3f> kp;
  std::vector<float> desc, lrf;
};

Described describe(const PointSet& c, bool fpfh, const LocalSettings& s) {
  const int dim = fpfh ? local::kFpfhDim : local::kShotDim;
  const std::vector<int> idx = local::voxel_keypoints(c, s.keypoint_voxel_mm);
  const std::vector<float> d = fpfh ? local::compute_fpfh(c, idx, s.descriptor_radius_mm, s.threads, s.max_support_points)
                                    : local::compute_shot(c, idx, s.descriptor_radius_mm, s.threads, s.max_support_points);
  const std::vector<float> l = local::compute_board_lrf(c, idx, s.lrf_radius_mm);
  Described out;
  for (size_t i = 0; i < idx.size(); ++i) {
    if (!local::finite_row(&d[i * dim], dim) || !local::finite_row(&l[i * 9], 9)) continue;
    out.kp.push_back(c.points[idx[i]]);
    out.desc.insert(out.desc.end(), &d[i * dim], &d[i * dim] + dim);
    out.lrf.insert(out.lrf.end(), &l[i * 9], &l[i * 9] + 9);
  }
  return out;
}

struct Fixture {
  DepthImage depth;
  Intrinsics K;
  RecognitionSettings s;
  PointSet scene;
  std::vector<int> scene_kp;
  std::vector<ViewData> views;
  std::vector<PointSet> model_clouds;  // views in the model frame (refinement sources)
  // Per descriptor (0 fpfh, 1 shot): described views and scene, the index,
  // and the matches per view.
  std::vector<Described> view_desc[2];
  Described scene_desc[2];
  std::vector<std::pair<int, int>> owner[2];  // index row -> (view, keypoint)
  std::unique_ptr<local::DescriptorIndex> index[2];
  std::vector<std::vector<local::Match>> matches[2];
};

const Fixture& fixture() {
  static const Fixture f = [] {
    Fixture f;
    const std::string yaml =
        "scenario: table\nseed: 7\nimages: 1\nsensor: synthetic\ntarget: ls5\n"
        "target_upright_probability: 1\n"
        "distractors: {pool: [milk_carton, boletus, box_small, cylinder], count: [3, 5]}\n"
        "occlusion: none\n";
    SceneGenerator gen(parse_scene_settings(YamlNode::load_string(yaml, "bench_local.yaml")));
    const GeneratedImage img = gen.generate(0);
    f.depth = img.depth;
    f.K = img.info.K;
    f.s.refinement = "icp";
    f.scene = preprocess_scene(OrganizedCloud::from_depth(f.depth, f.K), f.s.preprocess, 1);
    f.scene_kp = local::voxel_keypoints(f.scene, f.s.local.keypoint_voxel_mm);
    const auto rendered = render_training_views(gen.model("ls5").mesh, f.s.views);
    for (size_t i = 0; i < rendered.size(); ++i) {
      ViewData v;
      v.cloud = preprocess_view(rendered[i].cloud, f.s.preprocess, derive_seed(f.s.seed, {i}));
      v.T_cam_model = rendered[i].T_cam_model;
      PointSet m = v.cloud;
      const Pose T = v.T_cam_model.inverse();
      for (auto& p : m.points) p = (T * p.cast<double>()).cast<float>();
      for (auto& n : m.normals) n = (T.R * n.cast<double>()).cast<float>();
      f.model_clouds.push_back(std::move(m));
      f.views.push_back(std::move(v));
    }
    for (int d = 0; d < 2; ++d) {
      const bool fpfh = d == 0;
      const int dim = fpfh ? local::kFpfhDim : local::kShotDim;
      std::vector<float> all;
      for (size_t v = 0; v < f.views.size(); ++v) {
        f.view_desc[d].push_back(describe(f.views[v].cloud, fpfh, f.s.local));
        all.insert(all.end(), f.view_desc[d].back().desc.begin(), f.view_desc[d].back().desc.end());
        for (size_t k = 0; k < f.view_desc[d].back().kp.size(); ++k)
          f.owner[d].emplace_back(static_cast<int>(v), static_cast<int>(k));
      }
      f.index[d] = std::make_unique<local::DescriptorIndex>();
      f.index[d]->build(all, dim);
      f.scene_desc[d] = describe(f.scene, fpfh, f.s.local);
      const float thr = static_cast<float>(fpfh ? f.s.local.fpfh_match_threshold : f.s.local.match_threshold);
      f.matches[d].resize(f.views.size());
      std::vector<std::pair<int, float>> nn;
      for (size_t i = 0; i < f.scene_desc[d].kp.size(); ++i) {
        f.index[d]->knn(&f.scene_desc[d].desc[i * dim], f.s.local.matches_per_keypoint, thr, nn);
        for (const auto& [row, d2] : nn)
          f.matches[d][f.owner[d][row].first].push_back({f.owner[d][row].second, static_cast<int>(i), d2});
      }
    }
    return f;
  }();
  return f;
}

void BM_Keypoints(benchmark::State& state) {
  const Fixture& f = fixture();
  size_t n = 0;
  for (auto _ : state) n = local::voxel_keypoints(f.scene, f.s.local.keypoint_voxel_mm).size();
  state.counters["scene_points"] = static_cast<double>(f.scene.size());
  state.counters["keypoints"] = static_cast<double>(n);
}

// Descriptors at the scene keypoints; threads as the argument. Each stage
// of ours has PCL's beside it (the *Pcl benchmarks: the reference
// implementations kept for the tests), on the same keypoints and cloud.
using Describe = std::vector<float> (*)(const PointSet&, const std::vector<int>&, double, int);
void describe_bench(benchmark::State& state, Describe fn) {
  const Fixture& f = fixture();
  const int threads = static_cast<int>(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(fn(f.scene, f.scene_kp, f.s.local.descriptor_radius_mm, threads).data());
  state.counters["keypoints"] = static_cast<double>(f.scene_kp.size());
}
void BM_Fpfh(benchmark::State& state) {
  describe_bench(state, [](const PointSet& c, const std::vector<int>& k, double r, int t) {
    return local::compute_fpfh(c, k, r, t, fixture().s.local.max_support_points);
  });
}
// The same with no cap (every neighbour, PCL's definition; the single-pass
// path): where the cap does not bind, the two must take the same time.
void BM_FpfhUncapped(benchmark::State& state) {
  describe_bench(state, [](const PointSet& c, const std::vector<int>& k, double r, int t) {
    return local::compute_fpfh(c, k, r, t, 0);
  });
}
void BM_FpfhPcl(benchmark::State& state) { describe_bench(state, local::compute_fpfh_pcl); }
void BM_Shot(benchmark::State& state) {
  describe_bench(state, [](const PointSet& c, const std::vector<int>& k, double r, int t) {
    return local::compute_shot(c, k, r, t, fixture().s.local.max_support_points);
  });
}
void BM_ShotPcl(benchmark::State& state) { describe_bench(state, local::compute_shot_pcl); }
void BM_BoardLrf(benchmark::State& state) {
  const Fixture& f = fixture();
  for (auto _ : state)
    benchmark::DoNotOptimize(local::compute_board_lrf(f.scene, f.scene_kp, f.s.local.lrf_radius_mm).data());
  state.counters["keypoints"] = static_cast<double>(f.scene_kp.size());
}
void BM_BoardLrfPcl(benchmark::State& state) {
  const Fixture& f = fixture();
  for (auto _ : state)
    benchmark::DoNotOptimize(local::compute_board_lrf_pcl(f.scene, f.scene_kp, f.s.local.lrf_radius_mm).data());
  state.counters["keypoints"] = static_cast<double>(f.scene_kp.size());
}

// All scene keypoints against the descriptors of every view (one thread);
// the argument is match_max_checks (0 = exact). Counter `recall`: the share
// of the keypoints the exact search matches that get the same match here.
void BM_Match(benchmark::State& state, int d) {
  const Fixture& f = fixture();
  const int dim = d == 0 ? local::kFpfhDim : local::kShotDim;
  const float thr = static_cast<float>(d == 0 ? f.s.local.fpfh_match_threshold : f.s.local.match_threshold);
  const int n = static_cast<int>(f.scene_desc[d].kp.size());
  const int checks = static_cast<int>(state.range(0));
  using Result = std::vector<std::vector<std::pair<int, float>>>;
  const auto match = [&](int max_checks, Result& nn) {
    for (int first = 0; first < n; first += 32)  // blocks of 32 queries, as the method
      f.index[d]->knn_block(&f.scene_desc[d].desc[static_cast<size_t>(first) * dim], std::min(32, n - first),
                            f.s.local.matches_per_keypoint, thr, nn.data() + first, max_checks);
  };
  Result nn(static_cast<size_t>(n)), exact(static_cast<size_t>(n));
  for (auto _ : state) match(checks, nn);
  match(0, exact);
  size_t kept = 0, matched = 0, same = 0;
  for (int i = 0; i < n; ++i) {
    kept += nn[i].size();
    if (exact[i].empty()) continue;
    ++matched;
    same += nn[i] == exact[i];
  }
  state.counters["model_descriptors"] = static_cast<double>(f.index[d]->size());
  state.counters["scene_descriptors"] = static_cast<double>(f.scene_desc[d].kp.size());
  state.counters["matches"] = static_cast<double>(kept);
  state.counters["recall"] = matched ? static_cast<double>(same) / static_cast<double>(matched) : 1.0;
}

// 3D Hough voting of every view's matches.
void BM_Hough(benchmark::State& state, int d) {
  const Fixture& f = fixture();
  local::HoughParams hp;
  hp.bin_mm = f.s.local.hough_bin_mm;
  hp.min_votes = f.s.local.hough_min_votes;
  hp.interpolation = f.s.local.hough_interpolation;
  size_t clusters = 0;
  for (auto _ : state) {
    clusters = 0;
    for (size_t v = 0; v < f.views.size(); ++v)
      clusters += local::hough_grouping(f.view_desc[d][v].kp, f.view_desc[d][v].lrf, f.scene_desc[d].kp,
                                        f.scene_desc[d].lrf, f.matches[d][v], hp)
                      .size();
  }
  state.counters["clusters"] = static_cast<double>(clusters);
}

std::unique_ptr<Method> make(int d) { return d == 0 ? make_fpfh_method(fixture().s.local) : make_shot_method(fixture().s.local); }

void BM_Train(benchmark::State& state, int d) {
  const Fixture& f = fixture();
  for (auto _ : state) {
    auto m = make(d);
    m->train(f.views, f.s.seed);
  }
  state.counters["views"] = static_cast<double>(f.views.size());
}

// The whole online computation of one image, as recognize() runs it.
void BM_Online(benchmark::State& state, int d) {
  const Fixture& f = fixture();
  auto m = make(d);
  m->train(f.views, f.s.seed);
  const OrganizedCloud cloud = OrganizedCloud::from_depth(f.depth, f.K);
  StageTimes sum;
  double hyps = 0;
  for (auto _ : state) {
    StageTimes t;
    Timer timer;
    const PointSet scene = preprocess_scene(cloud, f.s.preprocess, 1);
    t.preprocess = timer.seconds();
    auto h = m->hypothesize(scene, f.views, 2, t);
    timer.reset();
    std::vector<Pose> refined;
    for (size_t i = 0; i < h.size(); ++i)
      refined.push_back(refine_pose(f.s.refinement, f.model_clouds[h[i].view], scene, h[i].T_cam_model, f.s.refine, i)
                            .T_cam_model);
    t.refine = timer.seconds();
    timer.reset();
    const PointIndex index(scene.points);
    int best = -1;
    for (size_t i = 0; i < h.size(); ++i)
      best = std::max(best, count_inliers(f.model_clouds[h[i].view].points, refined[i], index,
                                          f.s.verify.inlier_threshold_mm));
    t.verify = timer.seconds();
    benchmark::DoNotOptimize(best);
    sum.preprocess += t.preprocess;
    sum.describe += t.describe;
    sum.match += t.match;
    sum.group += t.group;
    sum.initial_pose += t.initial_pose;
    sum.refine += t.refine;
    sum.verify += t.verify;
    hyps += static_cast<double>(h.size());
  }
  const double n = static_cast<double>(state.iterations());
  state.counters["preprocess_s"] = sum.preprocess / n;
  state.counters["describe_s"] = sum.describe / n;
  state.counters["match_s"] = sum.match / n;
  state.counters["group_s"] = sum.group / n;
  state.counters["initial_pose_s"] = sum.initial_pose / n;
  state.counters["refine_s"] = sum.refine / n;
  state.counters["verify_s"] = sum.verify / n;
  state.counters["total_s"] = sum.total() / n;
  state.counters["hypotheses"] = hyps / n;
}

}  // namespace

BENCHMARK(BM_Keypoints)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Fpfh)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_FpfhUncapped)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_FpfhPcl)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Shot)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ShotPcl)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_BoardLrf)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_BoardLrfPcl)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Match, fpfh, 0)->Arg(0)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Match, shot, 1)->Arg(0)->Arg(16)->Arg(32)->Arg(64)->Arg(128)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Hough, fpfh, 0)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Hough, shot, 1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Train, fpfh, 0)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Train, shot, 1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Online, fpfh, 0)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Online, shot, 1)->Unit(benchmark::kMillisecond)->UseRealTime();

BENCHMARK_MAIN();
