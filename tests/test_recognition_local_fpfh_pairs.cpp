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

namespace pb {
namespace {

Vec3f unit(Rng& rng) {
  return Vec3f(static_cast<float>(rng.normal()), static_cast<float>(rng.normal()), static_cast<float>(rng.normal()))
      .normalized();
}

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
    PointSet cloud;  // 203 points: the last block of eight is short
    for (int k = 0; k < 203; ++k) {
      cloud.points.emplace_back(static_cast<float>(rng.uniform(-scale, scale)),
                                static_cast<float>(rng.uniform(-scale, scale)),
                                static_cast<float>(rng.uniform(-scale, scale)));
      cloud.normals.push_back(unit(rng));
    }
    const auto [np, nt] = check(cloud, "random, scale " + std::to_string(scale));
    pairs += np;
    taken += nt;
    // A plane with its normal (equal cosines), a line with normals along
    // it, duplicates, non-finite values.
    PointSet special;
    const Vec3f n0 = unit(rng), a = n0.unitOrthogonal(), b = n0.cross(a);
    for (int k = 0; k < 30; ++k) {
      special.points.push_back(scale * (static_cast<float>(rng.uniform(-1, 1)) * a +
                                        static_cast<float>(rng.uniform(-1, 1)) * b));
      special.normals.push_back(k % 2 ? n0 : Vec3f(-n0));
    }
    for (int k = 0; k < 8; ++k) {
      special.points.push_back(scale * static_cast<float>(k) * 0.1f * n0);
      special.normals.push_back(n0);
    }
    for (int k = 0; k < 5; ++k) {
      special.points.push_back(special.points[static_cast<size_t>(k)]);
      special.normals.push_back(unit(rng));
    }
    const float nan = std::numeric_limits<float>::quiet_NaN();
    special.points.emplace_back(nan, 0.f, 0.f);
    special.normals.push_back(n0);
    special.points.emplace_back(scale, scale, scale);
    special.normals.emplace_back(nan, nan, nan);
    check(special, "special, scale " + std::to_string(scale));
    // f1 = atan2(y, x) at its bin edges (f1 = -a, as in PpfPairKeys): the
    // point at the origin, its normal leaned by a from +x toward +z, the
    // other on the z axis with its normal in the xy plane.
    PointSet edges;
    const double width = 2 * M_PI / local::kSpfhBins;
    for (int k = -6; k <= 5; ++k)  // the edges -pi + m width, m = 0..11, are (k + 1/2) width
      for (int u = -3; u <= 3; ++u) {
        const float e = static_cast<float>((k + 0.5) * width);
        const float t = std::nextafter(e, u < 0 ? -10.f : 10.f) + static_cast<float>(u) * 1e-7f;
        edges.points.emplace_back(0.f, 0.f, 0.f);
        edges.normals.emplace_back(std::cos(t), 0.f, std::sin(t));
      }
    for (int k = 0; k < 8; ++k) {
      const float t = static_cast<float>(rng.uniform(-1.5, 1.5));
      edges.points.emplace_back(0.f, 0.f, 0.7f * scale);
      edges.normals.emplace_back(std::cos(t), std::sin(t), 0.f);
    }
    check(edges, "edges, scale " + std::to_string(scale));
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
    const Vec3f n2 = (line.cross(side) + 0.05f * unit(rng)).normalized();
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
