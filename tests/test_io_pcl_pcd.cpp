// Organized PCD export: header fields and binary payload parsed back without
// PCL (width x height, NaN for missing depth, coordinates as given).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

#include "core/error.h"
#include "io_pcl/pcd.h"
#include "temp_dir.h"

namespace fs = std::filesystem;
using namespace pb;

namespace {

using pbtest::TempDir;

struct Pcd {
  std::map<std::string, std::string> header;
  std::vector<float> xyz;
};

Pcd parse_pcd(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  Pcd p;
  size_t pos = 0;
  while (pos < bytes.size()) {
    const size_t eol = bytes.find('\n', pos);
    const std::string line = bytes.substr(pos, eol - pos);
    pos = eol + 1;
    if (line.empty() || line[0] == '#') continue;
    const size_t sp = line.find(' ');
    p.header[line.substr(0, sp)] = line.substr(sp + 1);
    if (line.rfind("DATA", 0) == 0) break;
  }
  const size_t n = (bytes.size() - pos) / 4;
  p.xyz.resize(n);
  std::memcpy(p.xyz.data(), bytes.data() + pos, n * 4);
  return p;
}

}  // namespace

TEST(Pcd, OrganizedBinaryWithNaNs) {
  TempDir tmp;
  Intrinsics K = Intrinsics::from_fov(8, 6, 60, 45);
  DepthImage d(8, 6);
  for (int v = 0; v < 6; ++v)
    for (int u = 0; u < 8; ++u) d.at(u, v) = (u + v) % 3 == 0 ? 0.f : 500.f + 10 * u + v;
  const OrganizedCloud c = OrganizedCloud::from_depth(d, K);
  const std::string path = tmp / "cloud.pcd";
  write_organized_pcd(path, c);
  EXPECT_FALSE(fs::exists(path + ".tmp"));
  const Pcd p = parse_pcd(path);
  EXPECT_EQ(p.header.at("WIDTH"), "8");
  EXPECT_EQ(p.header.at("HEIGHT"), "6");
  EXPECT_EQ(p.header.at("POINTS"), "48");
  EXPECT_EQ(p.header.at("DATA"), "binary");
  EXPECT_EQ(p.header.at("FIELDS"), "x y z");
  // PCL pads PointXYZ to 16 bytes in memory but writes x y z (12 bytes).
  ASSERT_EQ(p.xyz.size(), 48u * 3);
  int nan = 0;
  for (int i = 0; i < 48; ++i) {
    const Vec3f& q = c.points[i];
    if (!std::isfinite(q.z())) {
      EXPECT_TRUE(std::isnan(p.xyz[3 * i + 2])) << i;
      ++nan;
      continue;
    }
    EXPECT_EQ(p.xyz[3 * i + 0], q.x()) << i;
    EXPECT_EQ(p.xyz[3 * i + 1], q.y()) << i;
    EXPECT_EQ(p.xyz[3 * i + 2], q.z()) << i;
  }
  EXPECT_EQ(nan, 48 - static_cast<int>(d.valid_count()));
  EXPECT_GT(nan, 0);

  // Metres.
  write_organized_pcd(tmp / "m.pcd", d, K, 0.001);
  const Pcd m = parse_pcd(tmp / "m.pcd");
  EXPECT_FLOAT_EQ(m.xyz[3 * 1 + 2], 0.001f * d.at(1, 0));
}

TEST(Pcd, BadCloudOrPathIsAnInputError) {
  TempDir tmp;
  OrganizedCloud c;
  c.width = 4;
  c.height = 4;
  c.points.resize(3);
  EXPECT_THROW(write_organized_pcd(tmp / "x.pcd", c), InputError);
  c.points.assign(16, Vec3f(1, 2, 3));
  EXPECT_THROW(write_organized_pcd(tmp / "no_dir/x.pcd", c), InputError);
}
