// Images per second generating the table scenario (layout, occluder search,
// rendering, ground truth, noise), for the synthetic and the Astra sensor,
// and a whole scene set written to disk (PNG, masks, JSON).
#include <benchmark/benchmark.h>

#include <filesystem>

#include "core/yaml.h"
#include "scenes/generator.h"

namespace {

pb::SceneSettings table(const std::string& sensor, bool occluded) {
  std::string yaml = "scenario: table\nseed: 9\nimages: 1000\nsensor: " + sensor +
                     "\ntarget: ls5\n"
                     "distractors: {pool: [milk_carton, boletus, box_small, cylinder], count: [3, 8]}\n";
  yaml += occluded ? "occlusion: [0.4, 0.9]\n" : "occlusion: none\n";
  return pb::parse_scene_settings(pb::YamlNode::load_string(yaml, "bench.yaml"));
}

void generate_images(benchmark::State& state, const std::string& sensor, bool occluded) {
  pb::SceneGenerator gen(table(sensor, occluded));
  int im = 0;
  for (auto _ : state) {
    pb::GeneratedImage img = gen.generate(im++);
    benchmark::DoNotOptimize(img.depth.z.data());
  }
  state.counters["images_per_s"] = benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

void BM_TableSynthetic(benchmark::State& s) { generate_images(s, "synthetic", false); }
void BM_TableSyntheticOccluded(benchmark::State& s) { generate_images(s, "synthetic", true); }
void BM_TableAstra(benchmark::State& s) { generate_images(s, "astra", false); }
void BM_TableAstraOccluded(benchmark::State& s) { generate_images(s, "astra", true); }
void BM_TableKinectOne(benchmark::State& s) { generate_images(s, "kinect_one", false); }

// A 20-image scene set written to disk (BOP files, masks, preview) by as
// many worker threads as the argument (`posebench generate --threads`).
void BM_TableAstraDataset(benchmark::State& state) {
  pb::SceneSettings s = table("astra", false);
  s.images = 20;
  const int threads = static_cast<int>(state.range(0));
  const std::string out = (std::filesystem::temp_directory_path() / "posebench_bench_generate").string();
  for (auto _ : state) pb::generate_dataset(s, out, nullptr, threads);
  std::filesystem::remove_all(out);
  state.counters["images_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations() * s.images), benchmark::Counter::kIsRate);
}

}  // namespace

BENCHMARK(BM_TableSynthetic)->Unit(benchmark::kMillisecond)->MinTime(3.0)->UseRealTime();
BENCHMARK(BM_TableSyntheticOccluded)->Unit(benchmark::kMillisecond)->MinTime(3.0)->UseRealTime();
BENCHMARK(BM_TableAstra)->Unit(benchmark::kMillisecond)->MinTime(3.0)->UseRealTime();
BENCHMARK(BM_TableAstraOccluded)->Unit(benchmark::kMillisecond)->MinTime(3.0)->UseRealTime();
BENCHMARK(BM_TableKinectOne)->Unit(benchmark::kMillisecond)->MinTime(3.0)->UseRealTime();
BENCHMARK(BM_TableAstraDataset)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->Iterations(2)->UseRealTime();

BENCHMARK_MAIN();
