// OrganizedCloud::from_depth (core/types.h), four pixels at a time where the
// CPU has AVX2: every pixel's point is K.backproject(u, v, z) rounded to
// float, bit for bit, and NaN where the depth is no measurement (0,
// negative, NaN, infinite), for widths that are not a multiple of four and
// depths over the whole float range a sensor gives. (Reordering the double
// operations would seldom show after the rounding to float: the kernel keeps
// backproject's order by construction; this test catches a wrong operand,
// lane or mask.)
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

#include "core/cpu.h"
#include "core/random.h"
#include "core/types.h"

using namespace pb;

TEST(FromDepth, EveryPixelIsBackprojectBitForBit) {
  if (!cpu_has_avx2()) std::printf("no AVX2 on this CPU: the plain loop is checked\n");
  Rng rng(3);
  for (const int width : {1, 3, 4, 7, 640}) {
    const int height = 5;
    Intrinsics K;
    K.width = width;
    K.height = height;
    K.fx = rng.uniform(200, 900);
    K.fy = rng.uniform(200, 900);
    K.cx = rng.uniform(0, width);
    K.cy = rng.uniform(0, height);
    DepthImage d;
    d.width = width;
    d.height = height;
    d.z.resize(static_cast<size_t>(width) * height);
    const float special[] = {0.f, -1.f, std::numeric_limits<float>::quiet_NaN(),
                             std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity(),
                             std::numeric_limits<float>::denorm_min(), std::numeric_limits<float>::max()};
    for (size_t i = 0; i < d.z.size(); ++i)
      d.z[i] = i % 5 == 4 ? special[(i / 5) % 7] : static_cast<float>(rng.uniform(100, 9000));
    const OrganizedCloud c = OrganizedCloud::from_depth(d, K);
    ASSERT_EQ(c.points.size(), d.z.size());
    int valid = 0;
    for (int v = 0; v < height; ++v)
      for (int u = 0; u < width; ++u) {
        const float z = d.at(u, v);
        const Vec3f& p = c.points[static_cast<size_t>(v) * width + u];
        if (!(z > 0.f && std::isfinite(z))) {
          EXPECT_TRUE(std::isnan(p.x()) && std::isnan(p.y()) && std::isnan(p.z())) << "width " << width << " z " << z;
          continue;
        }
        ++valid;
        const Vec3f want = K.backproject(u, v, z).cast<float>();
        EXPECT_EQ(std::memcmp(p.data(), want.data(), sizeof(Vec3f)), 0)
            << "width " << width << " pixel (" << u << ", " << v << ") z " << z << ": " << p.transpose() << " vs "
            << want.transpose();
      }
    EXPECT_GT(valid, 0);
  }
}
