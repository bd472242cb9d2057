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
#include "recognition/ppf/internal.h"

namespace pb {
namespace {

Vec3f unit(Rng& rng) {
  Vec3f v(static_cast<float>(rng.normal()), static_cast<float>(rng.normal()), static_cast<float>(rng.normal()));
  return v.normalized();
}

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
      // Random points in a cube, random unit normals; 203 of them, so the
      // last block of eight is short.
      PointSet cloud;
      for (int k = 0; k < 203; ++k) {
        cloud.points.emplace_back(static_cast<float>(rng.uniform(-scale, scale)),
                                  static_cast<float>(rng.uniform(-scale, scale)),
                                  static_cast<float>(rng.uniform(-scale, scale)));
        cloud.normals.push_back(unit(rng));
      }
      compared += compare_all(cloud, step, rng, "random, scale " + std::to_string(scale));
      // Points on a plane with its normal (every cosine 0: PCL's acos test
      // decides the source), on a line with normals along it (a degenerate
      // frame), duplicates, and non-finite values.
      PointSet special;
      const Vec3f n0 = unit(rng);
      const Vec3f a = n0.unitOrthogonal(), b = n0.cross(a);
      for (int k = 0; k < 40; ++k) {
        special.points.push_back(scale * (static_cast<float>(rng.uniform(-1, 1)) * a +
                                          static_cast<float>(rng.uniform(-1, 1)) * b));
        special.normals.push_back(k % 2 ? n0 : Vec3f(-n0));
      }
      for (int k = 0; k < 10; ++k) {
        special.points.push_back(scale * static_cast<float>(k) * 0.1f * n0);
        special.normals.push_back(n0);
      }
      for (int k = 0; k < 6; ++k) {  // duplicates of earlier points
        special.points.push_back(special.points[static_cast<size_t>(k)]);
        special.normals.push_back(unit(rng));
      }
      const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
      special.points.emplace_back(nan, 0.f, 0.f);
      special.normals.push_back(n0);
      special.points.emplace_back(scale, scale, scale);
      special.normals.emplace_back(nan, nan, nan);
      special.points.emplace_back(inf, 0.f, scale);
      special.normals.push_back(n0);
      special.points.emplace_back(0.f, 0.f, 0.f);
      special.normals.emplace_back(0.f, 0.f, 0.f);
      // Angles at bin edges: the second normal turned about the first by a
      // multiple of the step, in a plane that makes f1 that angle.
      for (int k = -15; k <= 15; ++k) {
        const float t = static_cast<float>(k) * angle;
        for (const float eps : {-1e-6f, 0.f, 1e-6f}) {
          special.points.push_back(scale * (0.5f * a + 0.3f * n0));
          special.normals.push_back((std::cos(t + eps) * n0 + std::sin(t + eps) * b).normalized());
        }
      }
      compared += compare_all(special, step, rng, "special, scale " + std::to_string(scale));
      // f1 = atan2(y, x) at its bin edges: a reference at the origin with
      // its normal leaned by a from +x toward +z and a partner on the z axis
      // whose normal lies in the xy plane give f1 = -a (the source is the
      // reference, the partner's normal perpendicular to the line), for a
      // at every edge and a few floats either side of it.
      PointSet edges;
      for (int k = -15; k <= 15; ++k)
        for (int u = -3; u <= 3; ++u) {
          const float a = std::nextafter(static_cast<float>(k) * angle, u < 0 ? -10.f : 10.f) +
                          static_cast<float>(u) * 1e-7f;
          edges.points.emplace_back(0.f, 0.f, 0.f);
          edges.normals.emplace_back(std::cos(a), 0.f, std::sin(a));
        }
      for (int k = 0; k < 8; ++k) {
        const float t = static_cast<float>(rng.uniform(-1.5, 1.5));
        edges.points.emplace_back(0.f, 0.f, 0.7f * scale);
        edges.normals.emplace_back(std::cos(t), std::sin(t), 0.f);
      }
      compared += compare_all(edges, step, rng, "edges, scale " + std::to_string(scale));
    }
  }
  EXPECT_GT(compared, 400000u);
}

}  // namespace
}  // namespace pb
