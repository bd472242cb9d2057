// Rendering and sensor-noise speed: a 50k-triangle mesh at 640x480 (the
// astra profile), with and without normals and exact depth, and each noise
// model applied to a rendered image.
#include <benchmark/benchmark.h>

#include <cmath>

#include "render/renderer.h"
#include "render/sensor.h"

using namespace pb;

namespace {

// A torus of major radius R, minor radius r with n x m quads (2 n m triangles).
Mesh torus(float R, float r, int n, int m) {
  Mesh t;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < m; ++j) {
      const double a = 2 * M_PI * i / n, b = 2 * M_PI * j / m;
      t.vertices.emplace_back(static_cast<float>((R + r * std::cos(b)) * std::cos(a)),
                              static_cast<float>((R + r * std::cos(b)) * std::sin(a)),
                              static_cast<float>(r * std::sin(b)));
    }
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < m; ++j) {
      const int a = i * m + j, b = ((i + 1) % n) * m + j, c = ((i + 1) % n) * m + (j + 1) % m,
                d = i * m + (j + 1) % m;
      t.faces.push_back({a, b, c});
      t.faces.push_back({a, c, d});
    }
  return t;
}

Mesh wall() {
  Mesh w;
  w.vertices = {{-4000, -4000, 0}, {4000, -4000, 0}, {4000, 4000, 0}, {-4000, 4000, 0}};
  w.faces = {{0, 1, 2}, {0, 2, 3}};
  return w;
}

struct Fixture {
  SensorProfile sensor = sensor_profile("astra");
  Mesh mesh = torus(150.f, 60.f, 250, 100);  // 50,000 triangles
  Mesh back = wall();
  std::vector<RenderItem> items;
  Fixture() {
    Pose T;
    T.R = Eigen::AngleAxisd(0.6, Vec3(1, 0.3, 0).normalized()).toRotationMatrix();
    T.t = Vec3(0, 0, 800);
    Pose Tw;
    Tw.t = Vec3(0, 0, 1400);
    items = {{&mesh, T, 1}, {&back, Tw, 2}};
  }
};

Fixture& fixture() {
  static Fixture f;
  return f;
}

void render_bench(benchmark::State& state, bool normals, bool exact) {
  Fixture& f = fixture();
  RenderSettings rs;
  rs.normals = normals;
  rs.exact_depth = exact;
  DepthRenderer r(f.sensor.K, rs);
  size_t valid = 0;
  for (auto _ : state) {
    RenderOutput out = r.render(f.items);
    valid = out.depth.valid_count();
    benchmark::DoNotOptimize(out);
  }
  state.counters["triangles"] = static_cast<double>(f.mesh.faces.size() + f.back.faces.size());
  state.counters["valid_px"] = static_cast<double>(valid);
  state.SetItemsProcessed(state.iterations());
}

void BM_Render50k(benchmark::State& s) { render_bench(s, false, true); }
void BM_Render50kNormals(benchmark::State& s) { render_bench(s, true, true); }
void BM_Render50kDepthBuffer(benchmark::State& s) { render_bench(s, false, false); }

void noise_bench(benchmark::State& state, const std::string& model) {
  Fixture& f = fixture();
  DepthRenderer r(f.sensor.K, RenderSettings{50, 20000, true, true});
  const RenderOutput out = r.render(f.items);
  NoiseSettings n = f.sensor.noise;
  n.model = model;
  Rng rng(1);
  for (auto _ : state) {
    DepthImage d = out.depth;
    apply_noise(d, out, f.sensor, n, rng);
    benchmark::DoNotOptimize(d);
  }
  state.SetItemsProcessed(state.iterations());
}

void BM_NoiseGaussian(benchmark::State& s) { noise_bench(s, "gaussian"); }
void BM_NoiseStructuredLight(benchmark::State& s) { noise_bench(s, "structured_light"); }
void BM_NoiseTimeOfFlight(benchmark::State& s) { noise_bench(s, "tof"); }

}  // namespace

BENCHMARK(BM_Render50k)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Render50kNormals)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Render50kDepthBuffer)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_NoiseGaussian)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_NoiseStructuredLight)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_NoiseTimeOfFlight)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
