// Metric speed: MSSD and MSPD of a 10,000-vertex model with a continuous
// symmetry (ceil(pi / 0.01) = 315 discretized rotations), for an estimate
// near the truth (the usual case: a good bound early prunes most symmetries)
// and a wrong one; the thesis's errors over the same symmetry set; and VSD on
// one 640x480 image (two renders plus the per-pixel comparison).
#include <benchmark/benchmark.h>

#include <cmath>

#include "core/rotation.h"
#include "eval/bop_metrics.h"
#include "eval/errors.h"
#include "eval/symmetry.h"
#include "render/renderer.h"

using namespace pb;

namespace {

// An open cylinder (radius 50 mm, height 150 mm) of rings x segments
// vertices, symmetric about z.
Mesh cylinder(int rings, int segments) {
  Mesh m;
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const double a = 2 * M_PI * j / segments;
      m.vertices.emplace_back(static_cast<float>(50 * std::cos(a)), static_cast<float>(50 * std::sin(a)),
                              static_cast<float>(-75 + 150.0 * i / (rings - 1)));
    }
  for (int i = 0; i + 1 < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const int a = i * segments + j, b = i * segments + (j + 1) % segments;
      const int c = (i + 1) * segments + (j + 1) % segments, d = (i + 1) * segments + j;
      m.faces.push_back({a, b, c});
      m.faces.push_back({a, c, d});
    }
  return m;
}

Intrinsics vga() {
  Intrinsics K;
  K.width = 640;
  K.height = 480;
  K.fx = K.fy = 570;
  K.cx = 319.5;
  K.cy = 239.5;
  return K;
}

struct Fixture {
  Mesh mesh = cylinder(100, 100);  // 10,000 vertices
  std::vector<Pose> syms;
  Pose gt, near_est, wrong_est;
  Fixture() {
    ContinuousSymmetry c;
    syms = symmetry_transformations({}, {c});
    gt.R = axis_angle(Vec3(1, 0.2, 0), 1.2);
    gt.t = Vec3(30, -20, 900);
    Pose S;
    S.R = axis_angle(Vec3::UnitZ(), 1.234);  // a turn about the symmetry axis
    near_est = gt * S;
    near_est.R = axis_angle(Vec3(0.3, 1, 0.2), 2 * M_PI / 180) * near_est.R;  // plus 2 degrees
    near_est.t += Vec3(3, -4, 5);
    wrong_est.R = axis_angle(Vec3(1, 1, 0), 2.0) * gt.R;
    wrong_est.t = gt.t + Vec3(40, 10, -30);
  }
};

const Fixture& fixture() {
  static const Fixture f;
  return f;
}

void BM_MssdSymmetricNear(benchmark::State& state) {
  const Fixture& f = fixture();
  for (auto _ : state) benchmark::DoNotOptimize(mssd(f.near_est, f.gt, f.mesh.vertices, f.syms));
  state.counters["symmetries"] = static_cast<double>(f.syms.size());
  state.counters["vertices"] = static_cast<double>(f.mesh.vertices.size());
}
BENCHMARK(BM_MssdSymmetricNear)->Unit(benchmark::kMillisecond);

void BM_MssdSymmetricWrong(benchmark::State& state) {
  const Fixture& f = fixture();
  for (auto _ : state) benchmark::DoNotOptimize(mssd(f.wrong_est, f.gt, f.mesh.vertices, f.syms));
  state.counters["symmetries"] = static_cast<double>(f.syms.size());
}
BENCHMARK(BM_MssdSymmetricWrong)->Unit(benchmark::kMillisecond);

void BM_MssdNoSymmetry(benchmark::State& state) {
  const Fixture& f = fixture();
  for (auto _ : state) benchmark::DoNotOptimize(mssd(f.near_est, f.gt, f.mesh.vertices, {}));
}
BENCHMARK(BM_MssdNoSymmetry)->Unit(benchmark::kMillisecond);

void BM_MspdSymmetricNear(benchmark::State& state) {
  const Fixture& f = fixture();
  const Intrinsics K = vga();
  for (auto _ : state) benchmark::DoNotOptimize(mspd(f.near_est, f.gt, K, f.mesh.vertices, f.syms));
}
BENCHMARK(BM_MspdSymmetricNear)->Unit(benchmark::kMillisecond);

void BM_MspdSymmetricWrong(benchmark::State& state) {
  const Fixture& f = fixture();
  const Intrinsics K = vga();
  for (auto _ : state) benchmark::DoNotOptimize(mspd(f.wrong_est, f.gt, K, f.mesh.vertices, f.syms));
}
BENCHMARK(BM_MspdSymmetricWrong)->Unit(benchmark::kMillisecond);

void BM_ThesisErrorsSymmetric(benchmark::State& state) {
  const Fixture& f = fixture();
  for (auto _ : state) benchmark::DoNotOptimize(thesis_errors(f.near_est, f.gt, f.syms));
}
BENCHMARK(BM_ThesisErrorsSymmetric)->Unit(benchmark::kMicrosecond);

void BM_SymmetrySet(benchmark::State& state) {
  ContinuousSymmetry c;
  Mat4 D = Mat4::Identity();
  D.block<3, 3>(0, 0) = axis_angle(Vec3::UnitX(), M_PI);
  for (auto _ : state) benchmark::DoNotOptimize(symmetry_transformations({D}, {c}));
}
BENCHMARK(BM_SymmetrySet)->Unit(benchmark::kMicrosecond);

// VSD on a 640x480 image: renders the model at both poses, then compares.
void BM_Vsd640x480(benchmark::State& state) {
  const Fixture& f = fixture();
  const Intrinsics K = vga();
  DepthRenderer r(K);
  RenderItem it;
  it.mesh = &f.mesh;
  it.T_cam_model = f.gt;
  DepthImage scene = r.render({it}).depth;
  for (float& z : scene.z)
    if (z == 0.f) z = 1500.f;
  const double diameter = 2 * std::sqrt(50.0 * 50 + 75 * 75);
  long px = 0;
  for (auto _ : state) {
    const VsdResult v = vsd(f.near_est, f.gt, scene, f.mesh, diameter, r);
    px = v.union_px;
    benchmark::DoNotOptimize(v);
  }
  state.counters["union_px"] = static_cast<double>(px);
}
BENCHMARK(BM_Vsd640x480)->Unit(benchmark::kMillisecond);

// The per-pixel part alone (depths already rendered).
void BM_VsdFromRenders640x480(benchmark::State& state) {
  const Fixture& f = fixture();
  const Intrinsics K = vga();
  DepthRenderer r(K);
  RenderItem it;
  it.mesh = &f.mesh;
  it.T_cam_model = f.gt;
  const DepthImage dg = r.render({it}).depth;
  it.T_cam_model = f.near_est;
  const DepthImage de = r.render({it}).depth;
  DepthImage scene = dg;
  for (float& z : scene.z)
    if (z == 0.f) z = 1500.f;
  const double diameter = 2 * std::sqrt(50.0 * 50 + 75 * 75);
  for (auto _ : state) benchmark::DoNotOptimize(vsd_from_renders(de, dg, scene, K, diameter));
}
BENCHMARK(BM_VsdFromRenders640x480)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
