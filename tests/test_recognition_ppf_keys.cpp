// PPF's scene pair keys eight at a time (ppf::pair_keys, AVX2) against one
// at a time (ppf::pair_keys_plain, PCL's pair feature binned): the same pairs
// and keys, in the same order, bit for bit, on random clouds at several
// scales and on the cases where a lane must take the one-at-a-time path
// (coincident points, a normal along the line, cosines within 1e-6 of each
// other, an angle at a bin edge, NaN and infinite values, the reference as
// its own partner). And PPF's alpha_s eight at a time (ppf::approx_alpha_s)
// with the cells of its approximate value (ppf::VoteCells::checked): the
// bins and cells of pcl_alpha's value wherever they claim to be.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "core/atan2_bin.h"
#include "core/cpu.h"
#include "core/random.h"
#include "pair_feature_clouds.h"
#include "recognition/ppf/internal.h"

namespace pb {
namespace {


// Every point of `scene` as a reference, paired with every point (itself
// included, in a shuffled order), both ways; the count of pairs compared.
size_t compare_all(const PointSet& scene, const float step[4], Rng& rng, const std::string& what) {
  const size_t n = scene.size();
  std::vector<int> partners(n);
  std::iota(partners.begin(), partners.end(), 0);
  std::vector<int> point_a(n), point_b(n);
  std::vector<uint64_t> key_a(n), key_b(n);
  size_t compared = 0, wrong = 0;
  for (size_t r = 0; r < n; ++r) {
    std::shuffle(partners.begin(), partners.end(), rng);
    const Vec3f sr = scene.points[r], nr = scene.normals[r];
    const int self = static_cast<int>(r);
    const size_t ma = ppf::pair_keys(sr, nr, scene, partners.data(), n, self, step, point_a.data(), key_a.data());
    const size_t mb =
        ppf::pair_keys_plain(sr, nr, scene, partners.data(), n, self, step, point_b.data(), key_b.data());
    compared += n;
    if (ma != mb) {
      ADD_FAILURE() << what << ", reference " << r << ": " << ma << " pairs, one at a time " << mb;
      ++wrong;
      continue;
    }
    for (size_t k = 0; k < ma; ++k)
      if ((point_a[k] != point_b[k] || key_a[k] != key_b[k]) && ++wrong <= 5)
        ADD_FAILURE() << what << ", reference " << r << ", pair " << k << ": point " << point_a[k] << " key "
                      << key_a[k] << ", one at a time point " << point_b[k] << " key " << key_b[k];
  }
  EXPECT_EQ(wrong, 0u) << what;
  return compared;
}

TEST(PpfPairKeys, EightAtATimeEqualOneAtATime) {
  if (!cpu_has_avx2()) GTEST_SKIP() << "this CPU has no AVX2: pair_keys takes the one-at-a-time path only";
  Rng rng(77);
  const float deg12 = static_cast<float>(12 * M_PI / 180), deg7 = static_cast<float>(7 * M_PI / 180);
  size_t compared = 0;
  for (const float scale : {0.01f, 1.f, 100.f, 5000.f}) {
    for (const float angle : {deg12, deg7}) {
      const float step[4] = {angle, angle, angle, 0.05f * scale};
      const std::string at_scale = ", scale " + std::to_string(scale);
      compared += compare_all(pair_clouds::random_cloud(rng, scale), step, rng, "random" + at_scale);
      // The cases a lane leaves to the one-at-a-time path (PCL's acos test
      // decides the source on the plane, where every cosine is 0), and
      // second normals turned about the plane's normal by multiples of the
      // step.
      Vec3f n0;
      PointSet special = pair_clouds::special_cloud(rng, scale, &n0);
      const Vec3f a = n0.unitOrthogonal(), b = n0.cross(a);
      // Angles at bin edges: the second normal turned about the first by a
      // multiple of the step, in a plane that makes f1 that angle.
      for (int k = -15; k <= 15; ++k) {
        const float t = static_cast<float>(k) * angle;
        for (const float eps : {-1e-6f, 0.f, 1e-6f}) {
          special.points.push_back(scale * (0.5f * a + 0.3f * n0));
          special.normals.push_back((std::cos(t + eps) * n0 + std::sin(t + eps) * b).normalized());
        }
      }
      compared += compare_all(special, step, rng, "special" + at_scale);
      // f1 = atan2(y, x) at every bin edge.
      std::vector<float> at;
      for (int k = -15; k <= 15; ++k) at.push_back(static_cast<float>(k) * angle);
      const PointSet edges = pair_clouds::edge_cloud(rng, scale, at);
      compared += compare_all(edges, step, rng, "edges" + at_scale);
    }
  }
  EXPECT_GT(compared, 400000u);
}

// Points whose alpha_s in the frame T of reference (p, n) lies at each bin
// edge of `step` and a few floats either side: q = (x, cos e, -sin e) in
// the frame, taken back to the scene (the round trip moves it by ulps).
void add_alpha_edges(const Eigen::Affine3f& T, float scale, float step, PointSet& cloud) {
  const Eigen::Affine3f back = T.inverse();
  const int n = static_cast<int>(std::floor(2 * M_PI / step));
  for (int k = 0; k <= n; ++k) {
    const float e = static_cast<float>(k * static_cast<double>(step) - M_PI);
    for (int u = -3; u <= 3; ++u) {
      const float t = e + static_cast<float>(u) * 2e-7f;
      cloud.points.push_back(back * Vec3f(0.3f * scale, 0.5f * scale * std::cos(t), -0.5f * scale * std::sin(t)));
      cloud.normals.push_back(Vec3f::UnitZ());
    }
  }
}

// approx_alpha_s: wherever it gives a bin, that is the flags' bin of
// pcl_alpha's value, and its value lies within 2 * kAtan2BinWindow of
// pcl_alpha's; on random clouds at four scales, the special cases (points on
// the reference's normal line: a zero argument; NaN, inf), and points whose
// alpha_s lies at every bin edge, where most must be left to pcl_alpha.
TEST(PpfAlphaS, ApproximateBinsArePclAlphas) {
  if (!cpu_has_avx2()) GTEST_SKIP() << "this CPU has no AVX2: every alpha_s is pcl_alpha's";
  Rng rng(78);
  size_t compared = 0, approximated = 0, checked = 0, wrong = 0, edge_pairs = 0, edge_approximated = 0;
  for (const float scale : {0.01f, 1.f, 100.f, 5000.f}) {
    for (const double deg : {12.0, 7.0}) {
      const float step = static_cast<float>(deg * M_PI / 180);
      const PointSet random = pair_clouds::random_cloud(rng, scale), special = pair_clouds::special_cloud(rng, scale);
      for (size_t r = 0; r < random.size(); r += 7) {
        const Eigen::Affine3f T = ppf::to_reference_frame(random.points[r], random.normals[r]);
        PointSet cloud = random;
        cloud.points.insert(cloud.points.end(), special.points.begin(), special.points.end());
        cloud.normals.insert(cloud.normals.end(), special.normals.begin(), special.normals.end());
        for (int k = 0; k < 5; ++k) {  // on the normal line through the reference: q.y = q.z = 0
          cloud.points.push_back(random.points[r] + static_cast<float>(k) * scale * random.normals[r]);
          cloud.normals.push_back(random.normals[r]);
        }
        const size_t edges_from = cloud.size();
        add_alpha_edges(T, scale, step, cloud);
        std::vector<int> idx(cloud.size());
        std::iota(idx.begin(), idx.end(), 0);
        std::shuffle(idx.begin(), idx.end(), rng);
        std::vector<float> value(idx.size());
        std::vector<int> bin(idx.size());
        ppf::approx_alpha_s(T, cloud, idx.data(), idx.size(), step, value.data(), bin.data());
        for (size_t k = 0; k < idx.size(); ++k) {
          const bool at_edge = static_cast<size_t>(idx[k]) >= edges_from;
          edge_pairs += at_edge;
          const bool plain = static_cast<size_t>(idx[k]) < random.size();
          compared += plain;
          approximated += plain && bin[k] >= 0;
          if (bin[k] < 0) continue;
          ++checked;
          edge_approximated += at_edge;
          const float exact = ppf::pcl_alpha(T, cloud.points[static_cast<size_t>(idx[k])]);
          const int want = static_cast<int>(std::floor((exact + M_PI) / step));
          if ((want != bin[k] || !(std::fabs(value[k] - exact) <= 2 * kAtan2BinWindow)) && ++wrong <= 5)
            ADD_FAILURE() << "scale " << scale << ", " << deg << " deg, point " << idx[k] << ": bin " << bin[k]
                          << " value " << value[k] << ", pcl_alpha " << exact << " bin " << want;
        }
      }
    }
  }
  EXPECT_EQ(wrong, 0u) << "of " << checked;
  EXPECT_GT(approximated, compared * 95 / 100) << "on the random points the approximation is used";
  EXPECT_LT(edge_approximated, edge_pairs / 2) << "at the bin edges pcl_alpha decides";
}

// VoteCells::checked: cells from an alpha_s up to 2 * kAtan2BinWindow off
// the exact one are, wherever it returns true, the exact one's cells; with
// alpha_m at random (it returns true for most) and alpha_m a few floats from
// alpha_s + each bin edge and from +-pi (the wrap), where it must not.
TEST(PpfVoteCells, CheckedCellsAreTheExactAlphaSsCells) {
  if (!cpu_has_avx2()) GTEST_SKIP() << "this CPU has no AVX2: checked is always false";
  std::mt19937 rng(14);
  const float pi = static_cast<float>(M_PI);
  std::uniform_real_distribution<float> any(-pi, pi), off(-1, 1);
  size_t calls = 0, accepted = 0, wrong = 0, edge_calls = 0, edge_accepted = 0;
  for (const double deg : {12.0, 7.0}) {
    const float step = static_cast<float>(deg * M_PI / 180.0);
    const int n_alpha = std::max(1, static_cast<int>(std::floor(2 * M_PI / step)));
    const ppf::VoteCells cells(step, n_alpha);
    for (int t = 0; t < 20000; ++t) {
      const float exact = any(rng);
      const double shift = t % 3 == 0 ? 2 * kAtan2BinWindow * (t % 2 ? 1 : -1) : 2 * kAtan2BinWindow * off(rng);
      const float approx = static_cast<float>(exact + shift);
      const bool at_edge = t % 4 == 0;
      std::vector<float> alpha_m(1 + t % 23);
      for (float& a : alpha_m) a = any(rng);
      if (at_edge) {  // one vote a few floats from a bin edge or from the wrap
        const int k = static_cast<int>(rng() % static_cast<unsigned>(n_alpha + 1));
        double target = exact + k * static_cast<double>(step) - M_PI;
        if (t % 8 == 0) target = M_PI + exact;  // alpha = -pi + tiny or pi - tiny: the wrap
        while (target > M_PI) target -= 2 * M_PI;
        float a = static_cast<float>(target);
        for (int u = static_cast<int>(rng() % 7); u > 0; --u) a = std::nextafter(a, t % 16 < 8 ? -4.f : 4.f);
        alpha_m[rng() % alpha_m.size()] = std::max(-pi, std::min(pi, a));
      }
      std::vector<uint32_t> ref(alpha_m.size()), got(alpha_m.size()), want(alpha_m.size());
      for (auto& r : ref) r = static_cast<uint32_t>(rng() % 500);
      ++calls;
      edge_calls += at_edge;
      if (!cells.checked(ref.data(), alpha_m.data(), alpha_m.size(), approx, got.data())) continue;
      ++accepted;
      edge_accepted += at_edge;
      cells(ref.data(), alpha_m.data(), alpha_m.size(), exact, want.data());
      if (got != want && ++wrong <= 5)
        ADD_FAILURE() << deg << " deg, alpha_s " << exact << " approximated by " << approx << [&] {
          std::string d;
          for (size_t k = 0; k < got.size(); ++k)
            if (got[k] != want[k])
              d += " alpha_m " + std::to_string(alpha_m[k]) + " cell " + std::to_string(got[k] % n_alpha) + " vs " +
                   std::to_string(want[k] % n_alpha) + " ref " + std::to_string(got[k] / n_alpha) + "/" +
                   std::to_string(want[k] / n_alpha);
          return d;
        }();
    }
  }
  EXPECT_EQ(wrong, 0u) << "of " << accepted;
  EXPECT_GT(accepted - edge_accepted, (calls - edge_calls) * 9 / 10) << "at random, checked mostly holds";
  EXPECT_LT(edge_accepted, edge_calls / 10) << "near an edge it must not";
}

}  // namespace
}  // namespace pb
