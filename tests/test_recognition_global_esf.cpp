// Our ESF (global_esf.h): deterministic, thread-safe, and close to PCL's
// ESFEstimation on the same clouds compared with the distance between the
// ESFs of different objects.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <thread>

#include "core/cpu.h"
#include "core/hash.h"
#include "core/random.h"
#include "recognition/global/esf.h"
#include "recognition/global/esf_lines.h"
#include "recognition/global/internal.h"
#include "pcl_reference.h"  // PCL's implementation, the reference

namespace pb {
namespace {

// Points sampled uniformly (by area) on simple surfaces, in mm, placed in
// front of a camera at the origin.
using Sampler = std::function<Vec3f(Rng&)>;

std::vector<Vec3f> sample(const Sampler& f, int n, uint64_t seed) {
  Rng rng(seed);
  std::vector<Vec3f> pts;
  for (int i = 0; i < n; ++i) pts.push_back(f(rng) + Vec3f(10, -20, 700));
  return pts;
}

Vec3f on_box(Rng& r, float a, float b, float c) {
  const double areas[3] = {b * c, a * c, a * b};
  const double total = 2 * (areas[0] + areas[1] + areas[2]);
  double u = r.uniform() * total;
  const float s = r.uniform() < 0.5 ? -0.5f : 0.5f;
  const float x = static_cast<float>(r.uniform(-0.5, 0.5)), y = static_cast<float>(r.uniform(-0.5, 0.5));
  if ((u -= 2 * areas[0]) < 0) return {s * a, x * b, y * c};
  if ((u -= 2 * areas[1]) < 0) return {x * a, s * b, y * c};
  return {x * a, y * b, s * c};
}

std::vector<std::pair<std::string, Sampler>> shapes() {
  return {
      {"sphere",
       [](Rng& r) {
         Vec3 v(r.normal(), r.normal(), r.normal());
         return Vec3f((60.0 * v.normalized()).cast<float>());
       }},
      {"box", [](Rng& r) { return on_box(r, 160, 80, 40); }},
      {"cylinder",
       [](Rng& r) {
         const double a = r.uniform(0, 2 * M_PI);
         return Vec3f(static_cast<float>(30 * std::cos(a)), static_cast<float>(30 * std::sin(a)),
                      static_cast<float>(r.uniform(-90, 90)));
       }},
      {"torus",
       [](Rng& r) {
         // Rejection sampling for uniform area density.
         for (;;) {
           const double u = r.uniform(0, 2 * M_PI), v = r.uniform(0, 2 * M_PI);
           const double R = 60, rr = 18;
           if (r.uniform(0, R + rr) > R + rr * std::cos(v)) continue;
           return Vec3f(static_cast<float>((R + rr * std::cos(v)) * std::cos(u)),
                        static_cast<float>((R + rr * std::cos(v)) * std::sin(u)), static_cast<float>(rr * std::sin(v)));
         }
       }},
      {"plate", [](Rng& r) { return on_box(r, 150, 150, 6); }},
      {"half_sphere",
       [](Rng& r) {
         Vec3 v(r.normal(), r.normal(), -std::abs(r.normal()));
         return Vec3f((60.0 * v.normalized()).cast<float>());
       }},
  };
}

double l1(const std::vector<float>& a, const std::vector<float>& b) {
  double s = 0;
  for (size_t i = 0; i < a.size(); ++i) s += std::abs(static_cast<double>(a[i]) - b[i]);
  return s;
}
double l2(const std::vector<float>& a, const std::vector<float>& b) {
  double s = 0;
  for (size_t i = 0; i < a.size(); ++i) s += (static_cast<double>(a[i]) - b[i]) * (static_cast<double>(a[i]) - b[i]);
  return std::sqrt(s);
}

TEST(GlobalEsf, ShapeAndNormalization) {
  const auto pts = sample(shapes()[1].second, 3000, 1);
  Rng rng(7);
  const auto h = compute_esf(pts, rng);
  ASSERT_EQ(h.size(), 640u);
  double sum = 0;
  for (float v : h) {
    EXPECT_GE(v, 0.f);
    sum += v;
  }
  EXPECT_NEAR(sum, 1.0, 1e-4);
  // Degenerate input: zeros, no crash.
  Rng r2(1);
  const auto z = compute_esf({Vec3f(0, 0, 1), Vec3f(0, 0, 2)}, r2);
  ASSERT_EQ(z.size(), 640u);
  for (float v : z) EXPECT_EQ(v, 0.f);
  Rng r3(1);
  const auto line = compute_esf({Vec3f(0, 0, 1), Vec3f(0, 0, 2), Vec3f(0, 0, 3), Vec3f(0, 0, 4)}, r3);
  for (float v : line) EXPECT_EQ(v, 0.f);
}

// The histograms of every test shape, bit for bit, as tracing each line with
// its rounding steppers step by step computes them (the code reads the
// lines' minor-axis moves from a table instead): a change of the
// line tracing, the binning or the draws changes the fingerprint (on this
// toolchain: x86-64 without FMA contraction, glibc's acos).
TEST(GlobalEsf, HistogramsAreThoseOfTheSteppedLineTracing) {
  std::string bytes;
  for (const auto& [name, f] : shapes()) {
    Rng rng(11);
    const std::vector<float> h = compute_esf(sample(f, 2000, 5), rng);
    bytes.append(reinterpret_cast<const char*>(h.data()), h.size() * sizeof(float));
  }
  EXPECT_EQ(hash_hex(bytes), "ac09ddb762035115");
}

// The same for small clouds, where each point pair is drawn many times and
// its line's trace is looked up instead of traced again (CESF's stable
// regions have tens to hundreds of points): the fingerprint is that of
// tracing every line, so the lookup changes no bit.
TEST(GlobalEsf, SmallCloudsHaveTheHistogramsOfTracingEveryLine) {
  std::string bytes;
  for (int n : {3, 12, 40, 150, 400, 700}) {
    for (const auto& [name, f] : shapes()) {
      Rng rng(13 + static_cast<uint64_t>(n));
      const std::vector<float> h = compute_esf(sample(f, n, 7), rng);
      bytes.append(reinterpret_cast<const char*>(h.data()), h.size() * sizeof(float));
    }
  }
  EXPECT_EQ(hash_hex(bytes), "3fe602dc048ae871");
}

// A batch of lines traced eight at a time (AVX2) counts the voxels of each
// as tracing it alone: random grids of every density, lines between random
// voxels (one voxel long up to corner to corner, 63 steps), in batches of
// every size mod 8.
TEST(GlobalEsf, LinesEightAtATimeCountAsOneAtATime) {
  if (!pb::cpu_has_avx2()) GTEST_SKIP() << "this CPU has no AVX2: lines are traced one at a time only";
  using esf_detail::OccupancyGrid;
  Rng rng(17);
  size_t wrong = 0, checked = 0;
  for (int g = 0; g < 40; ++g) {
    OccupancyGrid grid;
    const int marks = rng.uniform_int(0, 3000);
    for (int k = 0; k < marks; ++k)
      grid.mark({rng.uniform_int(0, 63), rng.uniform_int(0, 63), rng.uniform_int(0, 63)});
    const size_t n = static_cast<size_t>(rng.uniform_int(1, 800));
    std::vector<Eigen::Vector3i> from(n), to(n);
    for (size_t k = 0; k < n; ++k) {
      from[k] = {rng.uniform_int(0, 63), rng.uniform_int(0, 63), rng.uniform_int(0, 63)};
      const int kind = rng.uniform_int(0, 9);
      to[k] = kind == 0 ? from[k]  // one voxel
              : kind == 1 ? Eigen::Vector3i(63 - from[k].x(), 63 - from[k].y(), 63 - from[k].z())
                          : Eigen::Vector3i(rng.uniform_int(0, 63), rng.uniform_int(0, 63), rng.uniform_int(0, 63));
    }
    std::vector<esf_detail::Line> fast(n), plain(n);
    esf_detail::trace_lines(grid, from.data(), to.data(), n, fast.data());
    esf_detail::trace_lines(grid, from.data(), to.data(), n, plain.data(), true);
    for (size_t k = 0; k < n; ++k, ++checked)
      if ((fast[k].count != plain[k].count || fast[k].occupied != plain[k].occupied || fast[k].cls != plain[k].cls) &&
          ++wrong <= 3)
        ADD_FAILURE() << "grid " << g << ", line " << k << ": " << fast[k].occupied << "/" << fast[k].count << " vs "
                      << plain[k].occupied << "/" << plain[k].count;
  }
  EXPECT_EQ(wrong, 0u) << "of " << checked;
}

// A3's bin from the table of bin edges equals the formula (acos): every
// float within 3000 ulps of each rounding edge (|cos| = cos((k + 1/2) / 63 x
// 90 deg)) and of each 1/1024th of [0, 1] (the lookup's cells), two million
// random ones in [0, 1], and the ends, values above 1, infinity and NaN.
TEST(GlobalEsf, AngleBinTableEqualsTheFormula) {
  size_t wrong = 0, checked = 0;
  auto check = [&](float c) {
    ++checked;
    if (esf_angle_bin(c) != esf_angle_bin_formula(c) && ++wrong <= 3)
      ADD_FAILURE() << "|cos| " << c << ": " << esf_angle_bin(c) << " vs " << esf_angle_bin_formula(c);
  };
  for (int k = -1; k <= kEsfBinsPerHistogram; ++k) {
    float c = static_cast<float>(std::cos((k + 0.5) / (kEsfBinsPerHistogram - 1) * M_PI / 2));
    for (int u = 0; u < 3000; ++u) c = std::nextafter(c, -1.f);
    for (int u = 0; u < 6000; ++u, c = std::nextafter(c, 2.f)) check(c);
  }
  for (int j = 0; j <= 1024; ++j) {  // around the lookup's cell boundaries j / 1024
    float c = static_cast<float>(j) / 1024;
    for (int u = 0; u < 50; ++u) c = std::nextafter(c, -1.f);
    for (int u = 0; u < 100; ++u, c = std::nextafter(c, 2.f)) check(c);
  }
  Rng rng(5);
  for (int i = 0; i < 2000000; ++i) check(static_cast<float>(rng.uniform()));
  for (const float c : {0.f, -0.f, 1e-45f, 1.f, std::nextafter(1.f, 2.f), 2.f, -1e-30f,
                        std::numeric_limits<float>::infinity(), std::numeric_limits<float>::quiet_NaN()})
    check(c);
  EXPECT_EQ(wrong, 0u) << "of " << checked;
}

// The rounding without std::lround equals it: exact halves of every bin and
// their neighbouring doubles, random values, values outside [0, 1], NaN.
TEST(GlobalEsf, UnitBinRoundsAsLround) {
  auto ref = [](double v) {
    return std::clamp(static_cast<int>(std::lround(v * (kEsfBinsPerHistogram - 1))), 0, kEsfBinsPerHistogram - 1);
  };
  size_t wrong = 0, checked = 0;
  auto check = [&](double v) {
    ++checked;
    if (esf_unit_bin(v) != ref(v) && ++wrong <= 3) ADD_FAILURE() << "v " << v;
  };
  for (int k = -3; k <= kEsfBinsPerHistogram + 2; ++k) {
    const double half = (k + 0.5) / (kEsfBinsPerHistogram - 1);
    double v = half;
    for (int u = 0; u < 50; ++u) v = std::nextafter(v, -10.0);
    for (int u = 0; u < 100; ++u, v = std::nextafter(v, 10.0)) check(v);
    check(k + 0.5);  // v * 63 lands on k + 0.5 exactly for some; these land on halves of 63 (k + 1/2) too
    check(-(k + 0.5) / (kEsfBinsPerHistogram - 1));
  }
  Rng rng(6);
  for (int i = 0; i < 1000000; ++i) check(rng.uniform(-2.0, 2.0));
  for (const double v : {0.0, -0.0, 1.0, 1e300, -1e300, 3e7, std::numeric_limits<double>::quiet_NaN()}) check(v);
  EXPECT_EQ(wrong, 0u) << "of " << checked;
}

TEST(GlobalEsf, DeterministicAndThreadSafe) {
  const auto pts = sample(shapes()[3].second, 3000, 2);
  Rng a(42), b(42), c(43);
  const auto ha = compute_esf(pts, a), hb = compute_esf(pts, b), hc = compute_esf(pts, c);
  EXPECT_EQ(ha, hb);  // bit for bit
  EXPECT_NE(ha, hc);  // another seed: other samples
  EXPECT_LT(l1(ha, hc), 0.2);

  // Two threads at once, each with its own generator, give the sequential
  // results.
  std::vector<float> t1, t2;
  const auto pts2 = sample(shapes()[1].second, 3000, 3);
  Rng s2(5);
  const auto seq2 = compute_esf(pts2, s2);
  std::thread th1([&] {
    Rng r(42);
    t1 = compute_esf(pts, r);
  });
  std::thread th2([&] {
    Rng r(5);
    t2 = compute_esf(pts2, r);
  });
  th1.join();
  th2.join();
  EXPECT_EQ(t1, ha);
  EXPECT_EQ(t2, seq2);
}

TEST(GlobalEsf, CloseToPclEsf) {
  const auto sh = shapes();
  std::vector<std::vector<float>> ours, pcls;
  double same_l1 = 0, same_l2 = 0, seed_l1 = 0;
  for (size_t i = 0; i < sh.size(); ++i) {
    const auto pts = sample(sh[i].second, 2500, 100 + i);
    Rng r(1000 + i), r2(2000 + i);
    ours.push_back(compute_esf(pts, r));
    pcls.push_back(global::pcl_esf(pts));
    const auto again = compute_esf(pts, r2);
    same_l1 += l1(ours.back(), pcls.back());
    same_l2 += l2(ours.back(), pcls.back());
    seed_l1 += l1(ours.back(), again);
    std::printf("  %-12s ours vs PCL: L1 %.4f L2 %.4f; ours, two seeds: L1 %.4f\n", sh[i].first.c_str(),
                l1(ours.back(), pcls.back()), l2(ours.back(), pcls.back()), l1(ours.back(), again));
  }
  const double n = static_cast<double>(sh.size());
  same_l1 /= n;
  same_l2 /= n;
  seed_l1 /= n;
  double diff_l1 = 0, diff_l2 = 0, min_diff_l1 = 1e9;
  int pairs = 0;
  for (size_t i = 0; i < sh.size(); ++i)
    for (size_t j = i + 1; j < sh.size(); ++j) {
      diff_l1 += l1(pcls[i], pcls[j]);
      diff_l2 += l2(pcls[i], pcls[j]);
      min_diff_l1 = std::min(min_diff_l1, l1(pcls[i], pcls[j]));
      ++pairs;
    }
  diff_l1 /= pairs;
  diff_l2 /= pairs;
  std::printf("ESF mean distance ours vs PCL (same cloud): L1 %.4f L2 %.4f\n", same_l1, same_l2);
  std::printf("ESF mean distance ours, two seeds (same cloud): L1 %.4f\n", seed_l1);
  std::printf("ESF mean distance PCL, different objects: L1 %.4f (min %.4f) L2 %.4f\n", diff_l1, min_diff_l1, diff_l2);
  // Ours and PCL's agree far better than different objects do, and every
  // object's own ESF is nearer to PCL's ESF of it than to PCL's of any other.
  EXPECT_LT(same_l1, 0.25 * diff_l1);
  // ... and differ by about as much as two of our runs with other seeds.
  EXPECT_LT(same_l1, 1.5 * seed_l1);
  EXPECT_LT(same_l2, 0.25 * diff_l2);
  for (size_t i = 0; i < sh.size(); ++i)
    for (size_t j = 0; j < sh.size(); ++j)
      if (i != j) EXPECT_LT(l1(ours[i], pcls[i]), l1(ours[i], pcls[j])) << sh[i].first << " vs " << sh[j].first;
}

}  // namespace
}  // namespace pb
