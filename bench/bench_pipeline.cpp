// recognize() end to end, per descriptor (fpfh shot cvfh esf cesf ourcvfh
// ppf, each with ICP refinement and the default settings: 12 training views),
// on one generated table image: the synthetic sensor (512 x 512, 1 mm
// Gaussian noise), the LS5 (the thesis's synthetic target) among 3-5
// distractors, no occluder. Each model is trained once, outside the timing.
//
// The benchmark's time is the wall time of one recognize() call (its CPU
// column: the CPU time of every thread of the process); the counters are the
// stage times it reports (RecognitionResult::times, seconds per image,
// averaged over the iterations): preprocess_s, describe_s, match_s, group_s,
// initial_pose_s, refine_s, verify_s and their sum total_s,
// plus the number of hypotheses, whether the chosen pose is correct by the
// thesis's table thresholds (symmetry-aware: the LS5 counts as symmetric
// about its axis, as in the thesis) and its errors (t_err_mm, r_err_deg).
// Set total_s beside the thesis's Table 4.1 (synthetic table: CVFH 0.19,
// ESF 0.60, CESF 0.43, SHOT 1.95, FPFH 1.22 s per image, on a 3 GHz
// two-core laptop CPU, thesis 1.6.1).
//
//   build/bench/bench_pipeline --benchmark_counters_tabular=true
// OpenMP parts (normals, FPFH/SHOT, matching, refinement of the hypotheses)
// use all cores unless OMP_NUM_THREADS says otherwise.
#include <benchmark/benchmark.h>

#include <map>
#include <memory>
#include <mutex>
#include <string>

#include "core/yaml.h"
#include "eval/errors.h"
#include "eval/symmetry.h"
#include "recognition/pipeline.h"
#include "../tests/recognition_train_util.h"
#include "scenes/generator.h"
#include "scenes/scene_config.h"

namespace {

using namespace pb;

constexpr char kScene[] = R"(
scenario: table
seed: 7
images: 1
sensor: synthetic
noise: {model: gaussian, sigma_mm: 1.0}
target: ls5
target_upright_probability: 1
min_target_visib: 0.9
distractors: {pool: [milk_carton, boletus, box_small, cylinder], count: [3, 5]}
occlusion: none
)";

struct Image {
  DepthImage depth;
  Intrinsics K;
  Pose gt;
  Mesh mesh;
  std::vector<Pose> symmetries;
};

const Image& image() {
  static const Image im = [] {
    Image im;
    SceneGenerator gen(parse_scene_settings(YamlNode::load_string(kScene, "bench_pipeline.yaml")));
    const GeneratedImage g = gen.generate(0);
    im.depth = g.depth;
    im.K = g.info.K;
    im.gt = g.info.gt.at(0).T_cam_model;
    im.mesh = gen.model("ls5").mesh;
    im.symmetries = symmetry_transformations(gen.model("ls5").info);
    return im;
  }();
  return im;
}

RecognitionSettings settings_for(const std::string& descriptor) {
  RecognitionSettings s;
  s.descriptor = descriptor;
  s.refinement = "icp";
  return s;
}

// One trained model per descriptor, built on first use (not timed).
std::shared_ptr<const TrainedModel> trained(const std::string& descriptor) {
  static std::mutex mu;
  static std::map<std::string, std::shared_ptr<const TrainedModel>> models;
  std::lock_guard<std::mutex> lock(mu);
  auto& m = models[descriptor];
  if (!m) m = test::train(image().mesh, settings_for(descriptor), TrainOptions{}, nullptr, "ls5");
  return m;
}

void BM_Recognize(benchmark::State& state, const std::string& descriptor) {
  const Image& im = image();
  const RecognitionSettings s = settings_for(descriptor);
  const auto model = trained(descriptor);
  StageTimes sum;
  double hyps = 0;
  RecognitionResult last;
  for (auto _ : state) {
    last = recognize(im.depth, im.K, *model, s);
    benchmark::DoNotOptimize(last.T_cam_model.t.data());
    sum.preprocess += last.times.preprocess;
    sum.describe += last.times.describe;
    sum.match += last.times.match;
    sum.group += last.times.group;
    sum.initial_pose += last.times.initial_pose;
    sum.refine += last.times.refine;
    sum.verify += last.times.verify;
    hyps += static_cast<double>(last.hypotheses.size());
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
  const ThesisThresholds thr = thesis_thresholds("table");
  ThesisErrorOptions eo;
  eo.thresholds = thr;
  if (last.status == "ok") {
    const ThesisErrors e = thesis_errors(last.T_cam_model, im.gt, im.symmetries, eo);
    state.counters["correct"] = thesis_correct(e, thr);
    state.counters["t_err_mm"] = e.translation_mm;
    state.counters["r_err_deg"] = e.rotation_deg;
  } else {
    state.counters["correct"] = 0;
  }
  state.SetLabel(last.status);
}

// Wall time per recognize() call; the CPU column is the CPU time of the whole
// process (every OpenMP thread), which a loaded machine inflates far less
// than the wall time.
void Configure(benchmark::internal::Benchmark* b) {
  b->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime()->MinTime(3.0);
}

}  // namespace

BENCHMARK_CAPTURE(BM_Recognize, fpfh_icp, std::string("fpfh"))->Apply(Configure);
BENCHMARK_CAPTURE(BM_Recognize, shot_icp, std::string("shot"))->Apply(Configure);
BENCHMARK_CAPTURE(BM_Recognize, cvfh_icp, std::string("cvfh"))->Apply(Configure);
BENCHMARK_CAPTURE(BM_Recognize, esf_icp, std::string("esf"))->Apply(Configure);
BENCHMARK_CAPTURE(BM_Recognize, cesf_icp, std::string("cesf"))->Apply(Configure);
BENCHMARK_CAPTURE(BM_Recognize, ourcvfh_icp, std::string("ourcvfh"))->Apply(Configure);
BENCHMARK_CAPTURE(BM_Recognize, ppf_icp, std::string("ppf"))->Apply(Configure);

BENCHMARK_MAIN();
