// Rest poses from the convex hull: boxes, tall cylinders, the LS5.
#include <gtest/gtest.h>

#include <cmath>

#include "core/random.h"
#include "models/procedural.h"
#include "scenes/rest_poses.h"

using namespace pb;

TEST(ConvexHull, CubeWithInteriorPoints) {
  std::vector<Vec3> pts;
  for (int i = 0; i < 8; ++i) pts.emplace_back(i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1);
  Rng rng(3);
  for (int i = 0; i < 500; ++i) pts.emplace_back(rng.uniform(-0.99, 0.99), rng.uniform(-0.99, 0.99), rng.uniform(-0.99, 0.99));
  const auto H = convex_hull_3d(pts);
  ASSERT_EQ(H.size(), 12u);  // 6 faces, 2 triangles each
  for (const auto& f : H) {
    for (int k = 0; k < 3; ++k) EXPECT_LT(f[k], 8);
    const Vec3 n = (pts[f[1]] - pts[f[0]]).cross(pts[f[2]] - pts[f[0]]);
    for (const auto& p : pts) EXPECT_LE(n.dot(p - pts[f[0]]), 1e-9);  // every point inside
  }
}

TEST(ConvexHull, RandomSphereCloudEnclosesAll) {
  Rng rng(5);
  std::vector<Vec3> pts;
  for (int i = 0; i < 3000; ++i) pts.emplace_back(rng.normal(), rng.normal(), rng.normal());
  const auto H = convex_hull_3d(pts);
  ASSERT_GT(H.size(), 20u);
  // Euler: a closed triangulated sphere has F = 2V - 4.
  std::set<int> verts;
  for (const auto& f : H)
    for (int k = 0; k < 3; ++k) verts.insert(f[k]);
  EXPECT_EQ(H.size(), 2 * verts.size() - 4);
  for (const auto& f : H) {
    const Vec3 n = (pts[f[1]] - pts[f[0]]).cross(pts[f[2]] - pts[f[0]]).normalized();
    for (const auto& p : pts) ASSERT_LE(n.dot(p - pts[f[0]]), 1e-6);
  }
}

TEST(ConvexHull, FlatInputIsEmpty) {
  std::vector<Vec3> pts{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0.5, 0.2, 0}};
  EXPECT_TRUE(convex_hull_3d(pts).empty());
}

TEST(RestPoses, BoxHasSixFacesLargestMostLikely) {
  const Mesh box = make_box(100, 60, 40);
  const RestPoses rp = compute_rest_poses(box);
  ASSERT_EQ(rp.poses.size(), 6u);
  double total = 0;
  for (const auto& p : rp.poses) total += p.probability;
  EXPECT_NEAR(total, 1.0, 1e-9);
  // The two 100 x 60 faces are the most likely, then 100 x 40, then 60 x 40.
  EXPECT_NEAR(std::abs(rp.poses[0].normal.z()), 1.0, 1e-9);
  EXPECT_NEAR(std::abs(rp.poses[1].normal.z()), 1.0, 1e-9);
  EXPECT_NEAR(std::abs(rp.poses[2].normal.y()), 1.0, 1e-9);
  EXPECT_NEAR(std::abs(rp.poses[4].normal.x()), 1.0, 1e-9);
  EXPECT_GT(rp.poses[0].probability, rp.poses[2].probability);
  EXPECT_GT(rp.poses[2].probability, rp.poses[4].probability);
  // Solid angles of a box's faces from its centre sum to 4 pi; the
  // 100 x 60 face: 4 asin(ab / sqrt((a^2 + d^2)(b^2 + d^2))) with half sizes.
  const double a = 50, b = 30, d = 20;
  const double omega = 4 * std::asin(a * b / std::sqrt((a * a + d * d) * (b * b + d * d)));
  EXPECT_NEAR(rp.poses[0].probability, omega / (4 * M_PI), 1e-9);
  // Upright: standing on -z, no rotation needed.
  ASSERT_GE(rp.upright, 0);
  EXPECT_NEAR(rp.poses[rp.upright].normal.z(), -1.0, 1e-9);
  EXPECT_TRUE(rp.poses[rp.upright].R_rest.isApprox(Mat3::Identity(), 1e-9));
  // Every R_rest turns its facet normal to -z.
  for (const auto& p : rp.poses) EXPECT_TRUE((p.R_rest * p.normal).isApprox(Vec3(0, 0, -1), 1e-9));
}

TEST(RestPoses, TallCylinderRarelyStandsAndLiesOnItsSide) {
  const Mesh cyl = make_cylinder(10, 200, 32);
  const RestPoses rp = compute_rest_poses(cyl);
  double ends = 0, sides = 0;
  for (const auto& p : rp.poses) (std::abs(p.normal.z()) > 0.99 ? ends : sides) += p.probability;
  EXPECT_LT(ends, 0.05);
  EXPECT_GT(sides, 0.95);
  ASSERT_GE(rp.upright, 0);  // standing is still a (rare) rest pose
}

TEST(RestPoses, UnstableFacetsAreExcluded) {
  // A prism leaning far over: its cross-section (y, z) is the parallelogram
  // (0,0) (10,0) (110,10) (100,10), extruded 100 mm along x. The centre of
  // mass (y = 55) lies far outside the 10 mm wide bottom and top faces, so
  // the object cannot rest on them; it rests on its long slanted sides or on
  // the end caps.
  Mesh m;
  const float L = 50;
  const float Y[4] = {0, 10, 110, 100}, Z[4] = {0, 0, 10, 10};
  for (int e = 0; e < 2; ++e)
    for (int k = 0; k < 4; ++k) m.vertices.emplace_back(e ? L : -L, Y[k], Z[k]);
  // Caps (counter-clockwise seen from outside) and sides.
  m.faces = {{0, 3, 2}, {0, 2, 1}, {4, 5, 6}, {4, 6, 7}};
  for (int k = 0; k < 4; ++k) {
    const int a = k, b = (k + 1) % 4;
    m.faces.emplace_back(a, b, b + 4);
    m.faces.emplace_back(a, b + 4, a + 4);
  }
  const RestPoses rp = compute_rest_poses(m);
  ASSERT_EQ(rp.poses.size(), 4u);  // two slanted sides, two caps
  for (const auto& p : rp.poses) {
    EXPECT_LT(std::abs(p.normal.z()), 0.999);  // not the flat 10 mm faces
    EXPECT_GT(p.margin_mm, 0.0);
  }
  // "Upright" is then the slanted side facing down (within 30 deg of -z).
  ASSERT_GE(rp.upright, 0);
  EXPECT_NEAR(rp.poses[rp.upright].normal.z(), -100.0 / std::sqrt(100.0 * 100.0 + 10.0 * 10.0), 1e-9);
  EXPECT_NEAR(rp.centre_of_mass.y(), 55.0, 1e-9);
}

TEST(RestPoses, Ls5StandsUpright) {
  const Mesh ls5 = make_ls5();
  const RestPoses rp = compute_rest_poses(ls5);
  ASSERT_GE(rp.upright, 0);
  EXPECT_NEAR(rp.poses[rp.upright].normal.z(), -1.0, 1e-6);
  // Lying on its side is possible too.
  int tipped = 0;
  for (const auto& p : rp.poses) tipped += std::abs(p.normal.z()) < 0.5;
  EXPECT_GT(tipped, 0);
  Rng rng(1);
  int upright = 0;
  for (int i = 0; i < 1000; ++i) upright += sample_rest_pose(rp, 0.5, rng) == rp.upright;
  EXPECT_GT(upright, 450);  // 0.5 plus its own share
}

TEST(Footprints, ConvexOverlapWithGap) {
  const std::vector<Eigen::Vector2d> a{{0, 0}, {10, 0}, {10, 10}, {0, 10}};
  std::vector<Eigen::Vector2d> b{{12, 0}, {20, 0}, {20, 10}, {12, 10}};
  EXPECT_FALSE(convex_polygons_overlap(a, b, 1.0));
  EXPECT_TRUE(convex_polygons_overlap(a, b, 3.0));
  b = {{5, 5}, {15, 5}, {15, 15}, {5, 15}};
  EXPECT_TRUE(convex_polygons_overlap(a, b, 0.0));
  const auto h = convex_hull_2d({{0, 0}, {1, 0}, {0.5, 0.5}, {1, 1}, {0, 1}, {0.5, 0}});
  EXPECT_EQ(h.size(), 4u);
}
