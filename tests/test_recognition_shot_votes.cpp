// SHOT's votes (recognition/local/shot_votes.h): the four-lane path adds the
// same bits to the histogram as the one-vote path, on random votes and on
// the borders where a vote's neighbours change (the shells' and halves'
// middles, the cosine bins' halves, zero coordinates, offsets along an axis).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>

#include "core/random.h"
#include "recognition/local/internal.h"
#include "recognition/local/shot_votes.h"

namespace {

using pb::Vec3f;
using pb::local::kShotDim;
using pb::local::ShotVotes;
using pb::local::ShotVotesIsa;

bool same_bits(const std::array<float, kShotDim + 1>& a, const std::array<float, kShotDim + 1>& b) {
  return std::memcmp(a.data(), b.data(), sizeof(float) * a.size()) == 0;
}

TEST(ShotVotes, FourLanesAddTheBitsOfOneVoteAtATime) {
  pb::Rng rng(5);
  const double radius = 40;
  // A frame turned away from the axes, and the axes themselves.
  const Vec3f z = Vec3f(0.2f, -0.3f, 0.93f).normalized(), x = Vec3f(1, 0.1f, 0).cross(z).normalized();
  const pb::local::ShotFrame turned{x, z.cross(x), z}, axes{Vec3f::UnitX(), Vec3f::UnitY(), Vec3f::UnitZ()};
  int compared = 0;
  for (const auto& f : {turned, axes}) {
    for (int trial = 0; trial < 200; ++trial) {
      ShotVotes v;
      const int n = rng.uniform_int(1, 40);
      for (int i = 0; i < n; ++i) {
        Vec3f o(static_cast<float>(rng.uniform(-radius, radius)), static_cast<float>(rng.uniform(-radius, radius)),
                static_cast<float>(rng.uniform(-radius, radius)));
        const int kind = rng.uniform_int(0, 9);
        // On the axes' frame: offsets with zero coordinates, on the axes and
        // at the elevation borders; at the shells' middles and border.
        if (kind == 0) o.x() = 0;
        if (kind == 1) o.y() = 0;
        if (kind == 2) o.z() = 0;
        if (kind == 3) o = Vec3f(0, 0, static_cast<float>(rng.uniform(-radius, radius)));
        if (kind == 4) o = Vec3f(10, 0, 10);  // 45 degrees
        double dist = o.cast<double>().norm();
        if (kind == 5) dist = radius / 4;
        if (kind == 6) dist = radius / 2;
        if (kind == 7) dist = radius * 3 / 4;
        if (!(dist > 0)) continue;
        float nz = static_cast<float>(rng.uniform(-1, 1));
        if (kind == 8) nz = static_cast<float>(rng.uniform_int(-5, 5)) / 5.f;  // the cosine bins' halves
        if (kind == 9) nz = rng.uniform_int(0, 1) ? 1.f : -1.f;
        v.push(o, nz, dist);
      }
      std::array<float, kShotDim + 1> one{}, four{};
      pb::local::add_shot_votes(v, f, radius, one.data(), ShotVotesIsa::scalar);
      pb::local::add_shot_votes(v, f, radius, four.data(), ShotVotesIsa::best);
      ASSERT_TRUE(same_bits(one, four)) << "trial " << trial << ", " << v.size() << " votes";
      EXPECT_EQ(one[kShotDim], 0.f) << "the spare slot only takes +0";
      ++compared;
    }
  }
  EXPECT_EQ(compared, 400);
}

}  // namespace
