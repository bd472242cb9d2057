// The preprocessing stage on simulated 640x480 Astra table frames
// (configs/scenes/table_astra.yaml, first image) and a warehouse frame
// (configs/scenes/warehouse_synthetic.yaml): depth -> organized cloud, the
// voxel grid, the RANSAC plane, normals, and the whole preprocess_scene at
// the settings of configs/bench/pipeline.yaml. One thread:
//   OMP_NUM_THREADS=1 build/bench/bench_preprocess
#include <benchmark/benchmark.h>

#include <string>

#include "core/yaml.h"
#include "recognition/kdtree.h"
#include "recognition/preprocess/internal.h"
#include "recognition/preprocess/preprocess.h"
#include "recognition/preprocess/voxel_grid.h"
#include "scenes/generator.h"
#include "scenes/scene_config.h"

namespace {

using namespace pb;

struct Frame {
  DepthImage depth;
  Intrinsics K;
  PreprocessSettings s;
};

Frame make_frame(const std::string& scene_file, bool warehouse) {
  const std::string path = std::string(POSEBENCH_SOURCE_DIR) + "/" + scene_file;
  SceneGenerator gen(parse_scene_settings(YamlNode::load_file(path)));
  const GeneratedImage g = gen.generate(0);
  Frame f{g.depth, g.info.K, {}};
  if (warehouse) {
    // As bench-pipeline resolves them for the LS5 (lengths scaled to its
    // size: records' settings_resolved.preprocess).
    f.s.voxel_mm = 20;
    f.s.max_range_mm = 9000;
    f.s.max_planes = 2;
    f.s.normal_radius_mm = 181.6;
    f.s.plane_threshold_mm = 90.8;
  }
  return f;
}

const Frame& frame(int which) {
  static const Frame table = make_frame("configs/scenes/table_astra.yaml", false);
  static const Frame warehouse = make_frame("configs/scenes/warehouse_synthetic.yaml", true);
  return which == 0 ? table : warehouse;
}

// Range-cut points with their pixels (as preprocess_scene's first step).
PointSet cut(const Frame& f) {
  const OrganizedCloud c = OrganizedCloud::from_depth(f.depth, f.K);
  PointSet ps;
  ps.source_width = c.width;  // the pixels index an image this wide
  ps.source_height = c.height;
  for (size_t i = 0; i < c.points.size(); ++i) {
    const Vec3f& p = c.points[i];
    if (!p.allFinite() || p.z() < f.s.min_range_mm || p.z() > f.s.max_range_mm) continue;
    ps.points.push_back(p);
    ps.pixel.push_back(static_cast<int>(i));
  }
  return ps;
}

void BM_FromDepth(benchmark::State& st) {
  const Frame& f = frame(static_cast<int>(st.range(0)));
  for (auto _ : st) benchmark::DoNotOptimize(OrganizedCloud::from_depth(f.depth, f.K).points.data());
}

void BM_VoxelGrid(benchmark::State& st) {
  const Frame& f = frame(static_cast<int>(st.range(0)));
  const PointSet ps = cut(f);
  size_t n = 0;
  for (auto _ : st) n = voxel_downsample(ps, {f.s.voxel_mm}).size();
  st.counters["in"] = static_cast<double>(ps.size());
  st.counters["out"] = static_cast<double>(n);
}

// The RANSAC plane as preprocess_scene runs it (candidates scored on a
// random subset of plane_sample_points, then the winner's inliers among all
// points and the refit).
void BM_Plane(benchmark::State& st) {
  const Frame& f = frame(static_cast<int>(st.range(0)));
  const PointSet ps = voxel_downsample(cut(f), {f.s.voxel_mm});
  for (auto _ : st)
    benchmark::DoNotOptimize(detail::ransac_plane(ps.points, f.s.plane_threshold_mm, f.s.plane_iterations, 1, nullptr,
                                                  f.s.plane_sample_points, f.s.plane_probability)
                                 .data());
  st.counters["points"] = static_cast<double>(ps.size());
}

void BM_Normals(benchmark::State& st) {
  const Frame& f = frame(static_cast<int>(st.range(0)));
  const PointSet ps = voxel_downsample(cut(f), {f.s.voxel_mm});
  for (auto _ : st) {
    PointSet c = ps;
    radius_normals(c, f.s.normal_radius_mm);
    benchmark::DoNotOptimize(c.normals.data());
  }
  st.counters["points"] = static_cast<double>(ps.size());
}

// The kd-tree over the downsampled cloud (normals, refinement crops and
// verification build one per cloud).
void BM_KdTreeBuild(benchmark::State& st) {
  const Frame& f = frame(static_cast<int>(st.range(0)));
  const PointSet ps = voxel_downsample(cut(f), {f.s.voxel_mm});
  for (auto _ : st) {
    const KdTree3 tree(ps.points);
    benchmark::DoNotOptimize(tree.size());
  }
  st.counters["points"] = static_cast<double>(ps.size());
}

// The whole preprocess_scene at the frame's settings, the planes removed
// after the grid (default) or before it (preprocess.planes_before_grid),
// reading every `stride`-th pixel of every `stride`-th row
// (preprocess.pixel_stride; the bench's warehouse takes 2). Counters: what
// preprocessing leaves (points) and, where asked, the grid's cells before
// the planes (cells).
void preprocess_scene_bench(benchmark::State& st, bool planes_first, int stride, bool count_cells) {
  const Frame& f = frame(static_cast<int>(st.range(0)));
  const OrganizedCloud c = OrganizedCloud::from_depth(f.depth, f.K);
  PreprocessSettings s = f.s;
  s.planes_before_grid = planes_first;
  s.pixel_stride = stride;
  size_t n = 0;
  for (auto _ : st) n = preprocess_scene(c, s, 1).size();
  st.counters["points"] = static_cast<double>(n);
  if (!count_cells) return;
  s.remove_plane = false;
  st.counters["cells"] = static_cast<double>(preprocess_scene(c, s, 1).size());
}

void BM_PreprocessScene(benchmark::State& st) { preprocess_scene_bench(st, false, 1, false); }
void BM_PreprocessScenePlanesFirst(benchmark::State& st) { preprocess_scene_bench(st, true, 1, false); }
void BM_PreprocessSceneStride(benchmark::State& st) {
  preprocess_scene_bench(st, false, static_cast<int>(st.range(1)), true);
}

void Args(benchmark::internal::Benchmark* b) {
  b->Arg(0)->Arg(1)->ArgName("warehouse")->Unit(benchmark::kMillisecond);
}

}  // namespace

BENCHMARK(BM_FromDepth)->Apply(Args);
BENCHMARK(BM_VoxelGrid)->Apply(Args);
BENCHMARK(BM_Plane)->Apply(Args);
BENCHMARK(BM_Normals)->Apply(Args);
BENCHMARK(BM_KdTreeBuild)->Apply(Args);
BENCHMARK(BM_PreprocessScene)->Apply(Args);
BENCHMARK(BM_PreprocessScenePlanesFirst)->Apply(Args);
BENCHMARK(BM_PreprocessSceneStride)
    ->ArgsProduct({{0, 1}, {1, 2}})
    ->ArgNames({"warehouse", "stride"})
    ->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
