// The global pipeline's stages on one generated table image (synthetic
// sensor, the LS5 among distractors, no occluder): preprocessing, scene
// segmentation, CRH, our ESF vs PCL's, and per method (cvfh, esf, cesf,
// ourcvfh) the whole online computation with its stage times as counters
// (preprocess, describe, match, initial pose, ICP refinement of every
// hypothesis, inlier count), to set beside the thesis's Table 4.1 times.
#include <benchmark/benchmark.h>

#include <memory>

#include "core/random.h"
#include "core/timer.h"
#include "core/yaml.h"
#include "recognition/global/esf.h"
#include "recognition/global/internal.h"
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

struct Fixture {
  DepthImage depth;
  Intrinsics K;
  RecognitionSettings s;
  PointSet scene;
  std::vector<ViewData> views;
  std::vector<PointSet> model_clouds;  // views in the model frame (refinement sources)
};

const Fixture& fixture() {
  static const Fixture f = [] {
    Fixture f;
    const std::string yaml =
        "scenario: table\nseed: 7\nimages: 1\nsensor: synthetic\ntarget: ls5\n"
        "target_upright_probability: 1\n"
        "distractors: {pool: [milk_carton, boletus, box_small, cylinder], count: [3, 5]}\n"
        "occlusion: none\n";
    SceneGenerator gen(parse_scene_settings(YamlNode::load_string(yaml, "bench_global.yaml")));
    const GeneratedImage img = gen.generate(0);
    f.depth = img.depth;
    f.K = img.info.K;
    f.s.refinement = "icp";
    f.scene = preprocess_scene(OrganizedCloud::from_depth(f.depth, f.K), f.s.preprocess, 1);
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
    return f;
  }();
  return f;
}

std::unique_ptr<Method> make(const std::string& name) {
  if (name == "cvfh") return make_cvfh_method(fixture().s.global);
  if (name == "esf") return make_esf_method(fixture().s.global);
  if (name == "cesf") return make_cesf_method(fixture().s.global);
  return make_ourcvfh_method(fixture().s.global);
}

void BM_Preprocess(benchmark::State& state) {
  const Fixture& f = fixture();
  const OrganizedCloud cloud = OrganizedCloud::from_depth(f.depth, f.K);
  for (auto _ : state) benchmark::DoNotOptimize(preprocess_scene(cloud, f.s.preprocess, 1).points.data());
  state.counters["points"] = static_cast<double>(f.scene.size());
}

// Scene segmentation: ours (a grid) and PCL's (a radius search per point),
// the same clusters; the argument multiplies the tolerance (1: the
// fixture's; 4: a tolerance of many voxels, as relative lengths give large
// objects on small voxels).
using Clusters = std::vector<std::vector<int>> (*)(const std::vector<Vec3f>&, double, int, int);
void clusters_bench(benchmark::State& state, Clusters fn) {
  const Fixture& f = fixture();
  const GlobalSettings& g = f.s.global;
  const double tol = g.cluster_tolerance_mm * static_cast<double>(state.range(0));
  size_t n = 0;
  for (auto _ : state) n = fn(f.scene.points, tol, g.cluster_min_points, g.cluster_max_points).size();
  state.counters["clusters"] = static_cast<double>(n);
}
void BM_EuclideanClusters(benchmark::State& state) { clusters_bench(state, global::euclidean_clusters); }
void BM_EuclideanClustersPcl(benchmark::State& state) { clusters_bench(state, global::euclidean_clusters_pcl); }

// ESF of one training view: ours (20000 samples, seeded) and PCL's. Ours
// also on the view's first N points (the argument; 0: all of them), the size
// of CESF's stable regions, where each point pair's trace is reused.
void BM_EsfOurs(benchmark::State& state) {
  const auto& all = fixture().views.front().cloud.points;
  const size_t n = state.range(0) > 0 ? std::min(all.size(), static_cast<size_t>(state.range(0))) : all.size();
  const std::vector<Vec3f> pts(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(n));
  for (auto _ : state) {
    Rng rng(1);
    benchmark::DoNotOptimize(compute_esf(pts, rng).data());
  }
  state.counters["points"] = static_cast<double>(pts.size());
}
void BM_EsfPcl(benchmark::State& state) {
  const auto& pts = fixture().views.front().cloud.points;
  for (auto _ : state) benchmark::DoNotOptimize(global::pcl_esf(pts).data());
}

void BM_CvfhView(benchmark::State& state) {
  const Fixture& f = fixture();
  for (auto _ : state) benchmark::DoNotOptimize(global::cvfh_signatures(f.views.front().cloud, f.s.global).size());
}

void BM_CrhSpectrumAndPeaks(benchmark::State& state) {
  const Fixture& f = fixture();
  const PointSet& v = f.views.front().cloud;
  const Vec3f axis = v.points.front().normalized();
  const auto V = global::crh_spectrum(v, axis);
  for (auto _ : state) {
    const auto S = global::crh_spectrum(v, axis);
    benchmark::DoNotOptimize(global::crh_roll_peaks(S, V, f.s.global).size());
  }
}

void BM_Train(benchmark::State& state, const std::string& name) {
  const Fixture& f = fixture();
  for (auto _ : state) {
    auto m = make(name);
    m->train(f.views, f.s.seed);
  }
  state.counters["views"] = static_cast<double>(f.views.size());
}

// The whole online computation of one image, as recognize() runs it.
void BM_Online(benchmark::State& state, const std::string& name) {
  const Fixture& f = fixture();
  auto m = make(name);
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
    sum.initial_pose += t.initial_pose;
    sum.refine += t.refine;
    sum.verify += t.verify;
    hyps += static_cast<double>(h.size());
  }
  const double n = static_cast<double>(state.iterations());
  state.counters["preprocess_s"] = sum.preprocess / n;
  state.counters["describe_s"] = sum.describe / n;
  state.counters["match_s"] = sum.match / n;
  state.counters["initial_pose_s"] = sum.initial_pose / n;
  state.counters["refine_s"] = sum.refine / n;
  state.counters["verify_s"] = sum.verify / n;
  state.counters["total_s"] = sum.total() / n;
  state.counters["hypotheses"] = hyps / n;
}

}  // namespace

BENCHMARK(BM_Preprocess)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_EuclideanClusters)->Arg(1)->Arg(4)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_EuclideanClustersPcl)->Arg(1)->Arg(4)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_EsfOurs)->Arg(0)->Arg(50)->Arg(150)->Arg(400)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_EsfPcl)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_CvfhView)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_CrhSpectrumAndPeaks)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Train, cvfh, std::string("cvfh"))->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Train, esf, std::string("esf"))->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Train, cesf, std::string("cesf"))->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Train, ourcvfh, std::string("ourcvfh"))->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Online, cvfh, std::string("cvfh"))->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Online, esf, std::string("esf"))->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Online, cesf, std::string("cesf"))->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Online, ourcvfh, std::string("ourcvfh"))->Unit(benchmark::kMillisecond)->UseRealTime();

BENCHMARK_MAIN();
