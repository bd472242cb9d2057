// PPF's scene pair keys eight at a time (ppf::pair_keys, AVX2) against one
// at a time (ppf::pair_keys_plain, PCL's pair feature binned): the same pairs
// and keys, in the same order, bit for bit, on random clouds at several
// scales and on the cases where a lane must take the one-at-a-time path
// (coincident points, a normal along the line, cosines within 1e-6 of each
// other, an angle at a bin edge, NaN and infinite values, the reference as
// its own partner).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>
#include <vector>

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

}  // namespace
}  // namespace pb
