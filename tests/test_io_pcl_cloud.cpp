// Point-cloud scenes (io/cloud.h): PCDs that PCL itself writes (ascii,
// binary, binary_compressed; metres or mm) read back to the depth image they
// came from, intrinsics fitted to an organized cloud, PLY clouds, and every
// malformed header or body named by file and field.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "core/error.h"
#include "io/cloud.h"
#include "io_pcl/pcd.h"
#include "temp_dir.h"

using namespace pb;

namespace {

// A 64 x 48 depth image: a tilted plane with a hole, in mm.
struct Scene {
  Intrinsics K = Intrinsics::from_K((Mat3() << 70, 0, 31.2, 0, 72, 24.6, 0, 0, 1).finished(), 64, 48);
  DepthImage depth{64, 48};
  Scene() {
    for (int v = 0; v < 48; ++v)
      for (int u = 0; u < 64; ++u)
        if (!(u > 20 && u < 30 && v > 10 && v < 20)) depth.at(u, v) = static_cast<float>(800 + 3.5 * u - 2.25 * v);
  }
};

std::string field_of(const std::string& path, const std::string& text) {
  try {
    parse_cloud(path, text, CloudUnits::automatic);
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), path);
    return e.field();
  }
  return "<no error>";
}

const char* kAsciiHeader =
    "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
    "WIDTH 3\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 3\nDATA ascii\n";

}  // namespace

TEST(IoCloud, PclWrittenPcdsReadBackToTheirDepthImage) {
  Scene s;
  pbtest::TempDir tmp("cloud");
  for (PcdEncoding enc : {PcdEncoding::binary, PcdEncoding::binary_compressed, PcdEncoding::ascii}) {
    for (double scale : {1.0, 0.001}) {
      const std::string path = tmp / ("c" + std::to_string(static_cast<int>(enc)) + "_" + std::to_string(scale) + ".pcd");
      write_organized_pcd(path, s.depth, s.K, scale, enc);
      const PointCloudFile c = read_cloud(path);
      SCOPED_TRACE(path);
      EXPECT_EQ(c.metres, scale < 1);  // told apart by the median depth
      ASSERT_EQ(c.width, 64);
      ASSERT_EQ(c.height, 48);
      const DepthImage d = organized_depth(c);
      // Exact in mm binary; metres and ascii round through fewer digits.
      const double tol = enc != PcdEncoding::ascii && scale == 1.0 ? 0.0 : 1e-4;
      for (size_t i = 0; i < d.z.size(); ++i) {
        EXPECT_EQ(d.z[i] == 0, s.depth.z[i] == 0) << i;
        EXPECT_NEAR(d.z[i], s.depth.z[i], tol * s.depth.z[i]) << i;
      }
      const Intrinsics K = fit_intrinsics(c, path);
      EXPECT_NEAR(K.fx, s.K.fx, 1e-4);
      EXPECT_NEAR(K.fy, s.K.fy, 1e-4);
      EXPECT_NEAR(K.cx, s.K.cx, 1e-4);
      EXPECT_NEAR(K.cy, s.K.cy, 1e-4);
      // The cloud projected through the true intrinsics is the depth image again.
      if (tol == 0) EXPECT_EQ(project_cloud(c, s.K).z, s.depth.z);
    }
  }
}

TEST(IoCloud, UnitsViewpointAndPly) {
  const std::string a = std::string(kAsciiHeader) + "0 0 1\n0.1 0 1\n0 0.1 1.2\n";
  EXPECT_TRUE(parse_cloud("a.pcd", a, CloudUnits::automatic).metres);
  EXPECT_EQ(parse_cloud("a.pcd", a, CloudUnits::automatic).points[2], Vec3f(0, 100, 1200));
  EXPECT_FALSE(parse_cloud("a.pcd", a, CloudUnits::millimetres).metres);
  EXPECT_EQ(parse_cloud("a.pcd", a, CloudUnits::millimetres).points[1], Vec3f(0.1f, 0, 1));
  // A sensor 0.5 m along x, turned 180 degrees about z: points come back in its frame.
  std::string v = a;
  v.replace(v.find("VIEWPOINT 0 0 0 1 0 0 0"), 23, "VIEWPOINT 0.5 0 0 0 0 0 1");
  const PointCloudFile c = parse_cloud("v.pcd", v, CloudUnits::metres);
  EXPECT_NEAR(c.points[0].x(), 500, 1e-3);
  EXPECT_NEAR(c.points[1].x(), 400, 1e-3);
  EXPECT_NEAR(c.points[2].y(), -100, 1e-3);
  // NaN in ascii is a hole; an organized ascii cloud.
  const PointCloudFile o = parse_cloud(
      "o.pcd", "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 2\nHEIGHT 2\nDATA ascii\n1 2 900\nnan nan nan\n3 4 950\n5 6 990\n",
      CloudUnits::automatic);
  EXPECT_TRUE(o.organized());
  EXPECT_FALSE(o.metres);
  EXPECT_FALSE(o.points[1].allFinite());
  EXPECT_EQ(organized_depth(o).z, (std::vector<float>{900, 0, 950, 990}));
  // A PLY cloud (vertices only) in mm.
  const PointCloudFile p = parse_cloud(
      "p.ply", "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\n"
               "property uchar red\nend_header\n1 2 700 255\n-1 -2 710 0\n",
      CloudUnits::automatic);
  EXPECT_FALSE(p.organized());
  EXPECT_EQ(p.points[1], Vec3f(-1, -2, 710));
  // The virtual camera sees every point.
  const Intrinsics K = virtual_camera(p, "p.ply");
  const DepthImage d = project_cloud(p, K);
  EXPECT_EQ(d.valid_count(), 2u);
}

TEST(IoCloud, MalformedFilesAreNamed) {
  const std::string pts = "0 0 1\n0.1 0 1\n0 0.1 1.2\n";
  const std::string h = kAsciiHeader;
  auto with = [&](const std::string& from, const std::string& to) {
    std::string s = h;
    s.replace(s.find(from), from.size(), to);
    return s;
  };
  EXPECT_EQ(field_of("a.pcd", h + pts), "<no error>");
  EXPECT_EQ(field_of("a.pcd", h + "0 0 1\n0.1 0 1\n"), "POINTS");                  // a point short
  EXPECT_EQ(field_of("a.pcd", h + pts + "1 1 1\n"), "point 3");                    // one too many
  EXPECT_EQ(field_of("a.pcd", h + "0 0 1\n0.1 x 1\n0 0 1\n"), "point 1");          // not a number
  EXPECT_EQ(field_of("a.pcd", h + "0 0 1\n0.1 1\n0 0 1\n"), "point 1");            // a value short
  EXPECT_EQ(field_of("a.pcd", with("POINTS 3", "POINTS 4") + pts), "POINTS");
  EXPECT_EQ(field_of("a.pcd", with("SIZE 4 4 4", "SIZE 4 4") + pts), "SIZE");
  EXPECT_EQ(field_of("a.pcd", with("SIZE 4 4 4", "SIZE 4 4 3") + pts), "SIZE");
  EXPECT_EQ(field_of("a.pcd", with("TYPE F F F", "TYPE F F Q") + pts), "TYPE");
  EXPECT_EQ(field_of("a.pcd", with("FIELDS x y z", "FIELDS x y w") + pts), "FIELDS");
  EXPECT_EQ(field_of("a.pcd", with("WIDTH 3", "WIDTH 0") + pts), "WIDTH");
  EXPECT_EQ(field_of("a.pcd", with("WIDTH 3", "WIDTH 99999999999") + pts), "WIDTH");
  EXPECT_EQ(field_of("a.pcd", with("DATA ascii", "DATA zip") + pts), "DATA");
  EXPECT_EQ(field_of("a.pcd", with("DATA ascii\n", "")), "DATA");                  // no DATA line
  EXPECT_EQ(field_of("a.pcd", with("VERSION 0.7", "COLOUR 7") + pts), "COLOUR");
  EXPECT_EQ(field_of("a.pcd", with("VIEWPOINT 0 0 0 1 0 0 0", "VIEWPOINT 0 0 0 0 0 0 0") + pts), "VIEWPOINT");
  EXPECT_EQ(field_of("a.pcd", h + "nan nan nan\nnan 0 0\ninf 0 1\n"), "points");  // nothing finite
  // Binary data shorter than declared; compressed data with wrong sizes or corrupt.
  const std::string b = with("DATA ascii", "DATA binary");
  EXPECT_EQ(field_of("b.pcd", b + std::string(35, '\0')), "DATA");
  std::string nan9;
  for (int i = 0; i < 9; ++i) nan9 += std::string("\x00\x00\xc0\x7f", 4);
  EXPECT_EQ(field_of("b.pcd", b + nan9), "points");  // every coordinate NaN
  EXPECT_EQ(field_of("b.pcd", b + std::string(36, '\0')), "<no error>");
  const std::string c = with("DATA ascii", "DATA binary_compressed");
  auto u32 = [](uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
  EXPECT_EQ(field_of("c.pcd", c + u32(4) + u32(35) + "abcd"), "DATA");              // wrong uncompressed size
  EXPECT_EQ(field_of("c.pcd", c + u32(400) + u32(36) + "abcd"), "DATA");            // past the end
  EXPECT_EQ(field_of("c.pcd", c + u32(3) + u32(36) + std::string("\x20\x05\x00", 3)), "DATA");  // reference before the start
  EXPECT_EQ(field_of("c.txt", h + pts), "cloud");
  EXPECT_EQ(field_of("p.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n1\n"), "cloud");
}

// The fuzz seeds (fuzz/seeds/cloud_*): one 24 x 18 cloud in three encodings
// (binary_compressed with LZF back references, binary with an extra field,
// ascii) reads to the same points.
TEST(IoCloud, TheSeedEncodingsAgree) {
  const std::string dir = std::string(POSEBENCH_SOURCE_DIR) + "/fuzz/seeds/";
  const PointCloudFile b = read_cloud(dir + "cloud_24x18_binary.pcd");
  const PointCloudFile c = read_cloud(dir + "cloud_24x18_compressed.pcd");
  const PointCloudFile a = read_cloud(dir + "cloud_24x18_ascii.pcd");
  ASSERT_EQ(b.points.size(), 24u * 18u);
  ASSERT_EQ(c.points.size(), b.points.size());
  ASSERT_EQ(a.points.size(), b.points.size());
  size_t finite = 0;
  for (size_t i = 0; i < b.points.size(); ++i) {
    ASSERT_EQ(b.points[i].allFinite(), c.points[i].allFinite()) << i;
    ASSERT_EQ(b.points[i].allFinite(), a.points[i].allFinite()) << i;
    if (!b.points[i].allFinite()) continue;
    ++finite;
    EXPECT_EQ(b.points[i], c.points[i]) << i;
    EXPECT_LT((b.points[i] - a.points[i]).norm(), 1e-5 * b.points[i].norm()) << i;
  }
  EXPECT_GT(finite, 300u);
  EXPECT_EQ(read_cloud(dir + "cloud_60.ply").points.size(), 60u);
}
