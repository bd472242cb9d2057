// Time of each refinement method on one registration case, and of PPF
// training and matching (Google Benchmark). The case is the refinement
// test's first one (tests/test_recognition_refine_scenes.h): the asymmetric
// object on a table, rendered at 600..900 mm with 1 mm noise, the initial
// pose 10 degrees and 20 mm off. Two densities:
//   table: scene voxel 10 mm (the thesis's table value), model view 5 mm;
//   dense: scene and model view at 3 mm (about 3k scene points).
// Run: build/bench/bench_refine [--benchmark_filter=...]
#include <benchmark/benchmark.h>

#include <memory>

#include "../tests/test_recognition_refine_scenes.h"
#include "recognition/method.h"
#include "recognition/pipeline.h"
#include "recognition/refine/refine.h"
#include "recognition/registry.h"

namespace pb {
namespace {

constexpr uint64_t kSeed = 20160601;
const char* const kMethods[] = {"none", "icp", "icp_lm", "icp_plane", "gicp", "ndt"};

const refine_test::Case& registration_case(int density) {
  static const Mesh object = refine_test::asymmetric_object();
  static const refine_test::Case cases[2] = {
      [] {
        return refine_test::make_case(object, 0, kSeed);
      }(),
      [] {
        refine_test::CaseOptions o;
        o.preprocess.voxel_mm = 3;
        o.model_voxel_mm = 3;
        return refine_test::make_case(object, 0, kSeed, o);
      }()};
  return cases[density];
}

void BM_Refine(benchmark::State& state) {
  const std::string method = kMethods[state.range(0)];
  const auto& c = registration_case(static_cast<int>(state.range(1)));
  RefineResult r;
  for (auto _ : state) {
    r = refine_pose(method, c.model, c.scene, c.init, RefineSettings{}, 1);
    benchmark::DoNotOptimize(r);
  }
  state.SetLabel(method + (state.range(1) ? " dense" : " table"));
  state.counters["scene_points"] = static_cast<double>(c.scene.size());
  state.counters["model_points"] = static_cast<double>(c.model.size());
  state.counters["iterations"] = r.iterations;
  state.counters["t_err_mm"] = refine_test::translation_error(r.T_cam_model, c.gt);
  state.counters["R_err_deg"] = refine_test::rotation_error_deg(r.T_cam_model, c.gt);
}
BENCHMARK(BM_Refine)
    ->ArgsProduct({{0, 1, 2, 3, 4, 5}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->MinTime(0.5);

// PPF: the 12 training views of the asymmetric object (default
// preprocessing, 10 mm voxel), as the pipeline prepares them.
const std::vector<ViewData>& ppf_views() {
  static const std::vector<ViewData> views = [] {
    const Mesh object = refine_test::asymmetric_object();
    std::vector<ViewData> v;
    const auto dirs = refine_test::training_directions();
    for (size_t k = 0; k < dirs.size(); ++k) {
      const auto tv = refine_test::training_view(object, dirs[k], derive_seed(kSeed, {k}));
      v.push_back(ViewData{tv.cloud_cam, tv.T_cam_model});
    }
    return v;
  }();
  return views;
}

RecognitionSettings ppf_settings() {
  RecognitionSettings s;
  s.descriptor = "ppf";
  return s;
}

void BM_PpfTrain(benchmark::State& state) {
  RecognitionSettings s = ppf_settings();
  s.ppf.model_points = static_cast<int>(state.range(0));
  for (auto _ : state) {
    auto m = make_ppf_method(s.ppf);
    m->train(ppf_views(), s.seed);
    benchmark::DoNotOptimize(m);
  }
}
BENCHMARK(BM_PpfTrain)->Arg(150)->Arg(300)->Arg(600)->Unit(benchmark::kMillisecond)->MinTime(0.5);

void BM_PpfMatch(benchmark::State& state) {
  const RecognitionSettings s = ppf_settings();
  static const std::unique_ptr<Method> m = [&] {
    auto p = make_ppf_method(s.ppf);
    p->train(ppf_views(), s.seed);
    return p;
  }();
  const auto& c = registration_case(0);
  std::vector<Hypothesis> h;
  StageTimes t;
  for (auto _ : state) {
    h = m->hypothesize(c.scene, ppf_views(), 1, t);
    benchmark::DoNotOptimize(h);
  }
  state.counters["scene_points"] = static_cast<double>(c.scene.size());
  state.counters["hypotheses"] = static_cast<double>(h.size());
  state.counters["best_t_err_mm"] = h.empty() ? -1 : refine_test::translation_error(h[0].T_cam_model, c.gt);
}
BENCHMARK(BM_PpfMatch)->Unit(benchmark::kMillisecond)->MinTime(0.5);

}  // namespace
}  // namespace pb

BENCHMARK_MAIN();
