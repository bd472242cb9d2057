// FPFH's SPFH pairs eight at a time (local::spfh_pair_bins, AVX2) against
// their definition one at a time: darboux_pair (recognition/darboux.h) and
// the bins of fpfh.cpp's count_pair, f1 = atan2(y, x) binned by atan2f's
// angle (binned_atan2), f2 and f3 by clamped_bin. Every pair it decides must
// be symmetric and carry those bins bit for bit; on random clouds at several
// scales most pairs must be decided (the fast path is taken), and the cases
// it must leave to the caller are there too: coincident points, cosines of
// equal magnitude, a normal along the line, NaN, angles at bin edges.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "core/atan2_bin.h"
#include "core/cpu.h"
#include "core/random.h"
#include "recognition/darboux.h"
#include "recognition/local/internal.h"
#include "pair_feature_clouds.h"

namespace pb {
namespace {


// Every point of `cloud` against every point (or, `mates`, point 2i against
// 2i + 1 and back): decided pairs checked against the definition; returns
// {pairs, decided}.
std::pair<size_t, size_t> check(const PointSet& cloud, const std::string& what, bool mates = false) {
  const int n = static_cast<int>(cloud.size());
  std::vector<int> partners;
  std::vector<uint8_t> decided(static_cast<size_t>(n));
  std::vector<int> bins(3 * static_cast<size_t>(n));
  size_t pairs = 0, taken = 0, wrong = 0;
  for (int p = 0; p < n; ++p) {
    partners.clear();
    if (mates) partners.push_back(p ^ 1);
    for (int q = 0; q < n && !mates; ++q) partners.push_back(q);
    local::spfh_pair_bins(cloud, p, partners.data(), partners.size(), decided.data(), bins.data());
    for (size_t j = 0; j < partners.size(); ++j) {
      ++pairs;
      if (!decided[j]) continue;
      ++taken;
      const int q = partners[j];
      float y, x, f2, f3;
      bool symmetric = false;
      const bool ok = darboux_pair(cloud.points[static_cast<size_t>(p)], cloud.normals[static_cast<size_t>(p)],
                                   cloud.points[static_cast<size_t>(q)], cloud.normals[static_cast<size_t>(q)], &y, &x,
                                   f2, f3, &symmetric);
      const int want[3] = {
          binned_atan2(y, x,
                       [](float f1) {
                         return clamped_bin(local::kSpfhBins * ((f1 + M_PI) * local::kSpfhInv2Pi), local::kSpfhBins);
                       }),
          local::kSpfhBins + clamped_bin(local::kSpfhBins * ((f2 + 1.0) * 0.5), local::kSpfhBins),
          2 * local::kSpfhBins + clamped_bin(local::kSpfhBins * ((f3 + 1.0) * 0.5), local::kSpfhBins)};
      const int* got = bins.data() + 3 * j;
      if ((!ok || !symmetric || got[0] != want[0] || got[1] != want[1] || got[2] != want[2]) && ++wrong <= 5)
        ADD_FAILURE() << what << ", pair " << p << " " << q << ": ok " << ok << " symmetric " << symmetric
                      << ", bins " << got[0] << " " << got[1] << " " << got[2] << ", want " << want[0] << " "
                      << want[1] << " " << want[2];
    }
  }
  EXPECT_EQ(wrong, 0u) << what;
  return {pairs, taken};
}

TEST(SpfhPairBins, EightAtATimeEqualTheDefinition) {
  if (!cpu_has_avx2()) GTEST_SKIP() << "this CPU has no AVX2: every SPFH pair is computed one at a time";
  Rng rng(31);
  size_t pairs = 0, taken = 0;
  for (const float scale : {0.01f, 1.f, 100.f, 5000.f}) {
    const std::string at_scale = ", scale " + std::to_string(scale);
    const auto [np, nt] = check(pair_clouds::random_cloud(rng, scale), "random" + at_scale);
    pairs += np;
    taken += nt;
    check(pair_clouds::special_cloud(rng, scale), "special" + at_scale);
    // f1 = atan2(y, x) at its bin edges -pi + m width, m = 0..11, which are
    // (k + 1/2) width.
    std::vector<float> at;
    const double width = 2 * M_PI / local::kSpfhBins;
    for (int k = -6; k <= 5; ++k) at.push_back(static_cast<float>((k + 0.5) * width));
    check(pair_clouds::edge_cloud(rng, scale, at), "edges" + at_scale);
  }
  // Pairs whose f3 (the source normal's cosine to the line) lies within a
  // few ulps of a bin edge: there its last bit decides the bin, so the
  // lanes' operations must be darboux_pair's in its order. The first normal
  // is set to make the cosine an edge 2 m / 11 - 1 (|c| > 0.3), the second
  // about perpendicular to the line (the first point stays the source),
  // and the first normal's coordinates are then moved by a few ulps.
  PointSet near;
  for (int t = 0; t < 2000; ++t) {
    const Vec3f p1(static_cast<float>(rng.uniform(-50, 50)), static_cast<float>(rng.uniform(-50, 50)),
                   static_cast<float>(rng.uniform(-50, 50)));
    const Vec3f p2(static_cast<float>(rng.uniform(-50, 50)), static_cast<float>(rng.uniform(-50, 50)),
                   static_cast<float>(rng.uniform(-50, 50)));
    const Vec3f line = (p2 - p1).normalized();
    const Vec3f side = line.unitOrthogonal();
    const int m = rng.uniform_int(0, 3) + (rng.uniform_int(0, 1) ? 0 : 8);  // 2m/11 - 1 in +-(0.45..1)
    const float c = 2.f * static_cast<float>(m + 1) / local::kSpfhBins - 1.f;
    const Vec3f n1 = (c * line + std::sqrt(1 - c * c) * side).normalized();
    const Vec3f n2 = (line.cross(side) + 0.05f * pair_clouds::unit(rng)).normalized();
    for (int k = 0; k < 24; ++k) {
      Vec3f n = n1;
      const float to = k % 2 ? 10.f : -10.f;
      for (int step = 0; step < k / 2; ++step) n[k % 3] = std::nextafter(n[k % 3], to);
      float y, x, f2, f3;
      bool symmetric = false;
      if (!darboux_pair(p1, n, p2, n2, &y, &x, f2, f3, &symmetric)) continue;
      const double scaled = local::kSpfhBins * ((f3 + 1.0) * 0.5);
      if (std::abs(scaled - std::round(scaled)) > 2e-6) continue;
      near.points.push_back(p1);
      near.normals.push_back(n);
      near.points.push_back(p2);
      near.normals.push_back(n2);
    }
  }
  EXPECT_GT(near.size(), 1000u);
  check(near, "near bin edges", true);
  EXPECT_GT(pairs, 150000u);
  EXPECT_GT(taken, pairs * 9 / 10) << "most random pairs take the eight-at-a-time path";
}

}  // namespace
}  // namespace pb
