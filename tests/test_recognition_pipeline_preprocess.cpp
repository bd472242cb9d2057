// Preprocessing (range cut, voxel grid, seeded RANSAC plane removal,
// normals) and verification (PointIndex, count_inliers).
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cstring>
#include <limits>

#include "core/random.h"
#include "recognition/preprocess/preprocess.h"
#include "recognition/preprocess/internal.h"
#include "recognition/preprocess/voxel_grid.h"
#include "recognition/verify/verify.h"
#include "test_recognition_pipeline_util.h"

namespace {

using pb::PointSet;
using pb::Vec3f;

TEST(Voxel, CentroidsPclOrderAndNearestPixel) {
  PointSet in;
  // Two points in cell (0,0,0), one in (1,0,0), one in (0,0,1).
  in.points = {Vec3f(1, 1, 1), Vec3f(3, 3, 3), Vec3f(12, 1, 1), Vec3f(1, 1, 15)};
  in.pixel = {10, 11, 12, 13};
  const PointSet out = pb::voxel_downsample(in, {10.0});
  ASSERT_EQ(out.size(), 3u);
  // PCL's order: z index, then y, then x.
  EXPECT_TRUE(out.points[0].isApprox(Vec3f(2, 2, 2)));
  EXPECT_TRUE(out.points[1].isApprox(Vec3f(12, 1, 1)));
  EXPECT_TRUE(out.points[2].isApprox(Vec3f(1, 1, 15)));
  // Both points are equally near the centroid (2,2,2): the smaller pixel wins.
  EXPECT_EQ(out.pixel[0], 10);
  EXPECT_EQ(out.pixel[1], 12);
  EXPECT_EQ(out.pixel[2], 13);
  // Negative coordinates use floor, as pcl::VoxelGrid: -1 and 1 are in different cells.
  in.points = {Vec3f(-1, 0, 0), Vec3f(1, 0, 0)};
  in.pixel = {0, 1};
  EXPECT_EQ(pb::voxel_downsample(in, {10.0}).size(), 2u);
}

// n points of the plane z = ax x + ay y + z0 over |x|, |y| < half, with
// 1 mm Gaussian noise along z.
void add_noisy_plane(pb::Rng& rng, int n, double half, double ax, double ay, double z0, std::vector<Vec3f>& pts) {
  for (int i = 0; i < n; ++i) {
    const double x = rng.uniform(-half, half), y = rng.uniform(-half, half);
    pts.emplace_back(x, y, ax * x + ay * y + z0 + rng.normal(0, 1));
  }
}

TEST(Ransac, FindsThePlaneDeterministically) {
  pb::Rng rng(3);
  std::vector<Vec3f> pts;
  // A tilted plane z = 0.2 x + 500 with 1 mm noise, 2000 points, plus 500 outliers above it.
  add_noisy_plane(rng, 2000, 300, 0.2, 0, 500, pts);
  for (int i = 0; i < 500; ++i) {
    const double x = rng.uniform(-50, 50), y = rng.uniform(-50, 50);
    pts.emplace_back(x, y, 0.2 * x + 500 - rng.uniform(20, 120));
  }
  Eigen::Vector4d plane;
  const auto flags = pb::detail::ransac_plane(pts, 5.0, 100, 42, &plane);
  int missed = 0, outliers_on = 0;
  for (size_t i = 0; i < pts.size(); ++i) {
    if (i < 2000 && !flags[i]) ++missed;
    if (i >= 2000 && flags[i]) ++outliers_on;
  }
  EXPECT_LE(missed, 20);  // 5 sigma of the 1 mm noise: practically all plane points
  EXPECT_EQ(outliers_on, 0);
  const pb::Vec3 n_true = pb::Vec3(-0.2, 0, 1).normalized();
  EXPECT_GT(std::abs(plane.head<3>().dot(n_true)), 0.9999);
  EXPECT_EQ(flags, pb::detail::ransac_plane(pts, 5.0, 100, 42));
  // Degenerate input: no crash, no plane.
  EXPECT_EQ(pb::detail::ransac_plane({Vec3f(0, 0, 1), Vec3f(1, 0, 1)}, 5.0, 100, 1), std::vector<char>(2, 0));
  const std::vector<Vec3f> line = {Vec3f(0, 0, 1), Vec3f(1, 0, 1), Vec3f(2, 0, 1), Vec3f(3, 0, 1)};
  EXPECT_EQ(pb::detail::ransac_plane(line, 5.0, 50, 1), std::vector<char>(4, 0));
}

// Scored on a 500-point subset, RANSAC still selects the plane among all
// points (the subset only picks the winner), deterministically per seed.
TEST(Ransac, SubsetScoringSelectsThePlaneAmongAllPoints) {
  pb::Rng rng(5);
  std::vector<Vec3f> pts;
  add_noisy_plane(rng, 20000, 400, 0, 0.1, 800, pts);
  for (int i = 0; i < 3000; ++i) pts.emplace_back(rng.uniform(-60, 60), rng.uniform(-60, 60), rng.uniform(600, 760));
  const auto flags = pb::detail::ransac_plane(pts, 5.0, 100, 9, nullptr, 500);
  int on = 0, outliers_on = 0;
  for (size_t i = 0; i < pts.size(); ++i) {
    if (i < 20000) on += flags[i];
    else outliers_on += flags[i];
  }
  EXPECT_GE(on, 19900);
  EXPECT_EQ(outliers_on, 0);
  EXPECT_EQ(flags, pb::detail::ransac_plane(pts, 5.0, 100, 9, nullptr, 500));
  // The adaptive stop (probability 0.99: with 87% of the points on the
  // plane a handful of samples suffice) finds the same plane.
  const auto early = pb::detail::ransac_plane(pts, 5.0, 100, 9, nullptr, 500, 0.99);
  int differ = 0;
  for (size_t i = 0; i < pts.size(); ++i) differ += early[i] != flags[i];
  EXPECT_LE(differ, 100);  // boundary points of the 5 mm band (of 23000)
  for (size_t i = 20000; i < pts.size(); ++i) EXPECT_FALSE(early[i]) << i;
}

// A floor and a wall (the warehouse): max_planes 1 removes the larger one,
// max_planes 2 both; the object stays.
// RANSAC's scoring count equals the test written with Eigen (|n . p + d| <=
// thr, Vector3d dot product): random planes and points, thresholds equal to
// some points' own distances as Eigen computes them and the doubles either
// side (where another summation order would put a point on the other side),
// and zero and huge coordinates. The candidate planes score as with Eigen,
// bit for bit.
TEST(Ransac, CountWithinEqualsEigensTest) {
  using pb::Vec3;
  namespace detail = pb::detail;
  pb::Rng rng(9);
  size_t checked = 0;
  for (int trial = 0; trial < 300; ++trial) {
    Vec3 n(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
    if (n.norm() < 1e-3) continue;
    n.normalize();
    Eigen::Vector4d plane;
    plane << n, rng.uniform(-3000, 3000);
    std::vector<Vec3f> pts;
    for (int i = 0; i < 1000; ++i)
      pts.emplace_back(static_cast<float>(rng.uniform(-3000, 3000)), static_cast<float>(rng.uniform(-3000, 3000)),
                       static_cast<float>(rng.uniform(0, 5000)));
    pts.emplace_back(0.f, 0.f, 0.f);
    pts.emplace_back(-0.f, 1e30f, -1e30f);
    const detail::PlanePoints soa(pts);
    auto eigen_distance = [&](const Vec3f& p) {  // RANSAC's scoring written with Eigen
      const Vec3 pd = p.cast<double>();
      return std::abs(plane.head<3>().dot(pd) + plane[3]);
    };
    for (int k = 0; k < 20; ++k) {
      const double at = eigen_distance(pts[static_cast<size_t>(rng.uniform_int(0, 999))]);
      for (const double thr : {at, std::nextafter(at, 0.0), std::nextafter(at, 1e300)}) {
        size_t eigen = 0;
        for (const Vec3f& p : pts) eigen += eigen_distance(p) <= thr ? 1 : 0;
        EXPECT_EQ(detail::count_within(soa, plane, thr), eigen) << "trial " << trial << " thr " << thr;
        checked += pts.size();
      }
    }
  }
  EXPECT_GT(checked, 10000000u);
}

TEST(Preprocess, MaxPlanesRemovesFloorAndWall) {
  pb::OrganizedCloud cloud;
  cloud.width = 200;
  cloud.height = 1;
  pb::Rng rng(4);
  for (int i = 0; i < 6000; ++i) cloud.points.emplace_back(rng.uniform(-1500, 1500), 800, rng.uniform(2000, 5000));   // floor y = 800
  for (int i = 0; i < 4000; ++i) cloud.points.emplace_back(rng.uniform(-1500, 1500), rng.uniform(-800, 800), 5000);  // wall z = 5000
  for (int i = 0; i < 800; ++i) {  // an object: a ball of 200 mm radius
    const pb::Vec3 d = pb::Vec3(rng.normal(), rng.normal(), rng.normal()).normalized() * 200;
    cloud.points.push_back((pb::Vec3(0, 400, 3500) + d).cast<float>());
  }
  cloud.width = static_cast<int>(cloud.points.size());
  pb::PreprocessSettings s;
  s.max_range_mm = 9000;
  s.voxel_mm = 20;
  s.normal_radius_mm = 80;
  s.plane_threshold_mm = 20;
  s.min_plane_fraction = 0.1;
  auto count_near = [](const PointSet& ps, auto pred) {
    int n = 0;
    for (const auto& p : ps.points) n += pred(p);
    return n;
  };
  auto on_floor = [](const Vec3f& p) { return std::abs(p.y() - 800) < 5; };
  auto on_wall = [](const Vec3f& p) { return std::abs(p.z() - 5000) < 5; };
  auto on_ball = [](const Vec3f& p) { return (p - Vec3f(0, 400, 3500)).norm() < 230; };
  for (const bool first : {false, true}) {  // planes after the grid, and before it
    s.planes_before_grid = first;
    s.max_planes = 1;
    const PointSet one = pb::preprocess_scene(cloud, s, 3);
    EXPECT_EQ(count_near(one, on_floor), 0) << "planes first " << first;
    EXPECT_GT(count_near(one, on_wall), 1000) << "planes first " << first;
    s.max_planes = 2;
    const PointSet two = pb::preprocess_scene(cloud, s, 3);
    EXPECT_EQ(count_near(two, on_floor), 0) << "planes first " << first;
    EXPECT_EQ(count_near(two, on_wall), 0) << "planes first " << first;
    EXPECT_GT(count_near(two, on_ball), 400) << "planes first " << first;
  }
}

// A table seen through heavy noise (Gaussian, sigma 20 mm along the view
// axis, twice the 10 mm plane threshold) with a box standing on it: the fixed
// threshold leaves most of the table (its points beyond 10 mm); widened to
// plane_noise_factor x the depth noise measured in the image, the table goes
// (about 6% of it left) and the box above that band stays. On a clean table
// (sigma 1 mm) the widening changes nothing. The noise estimate itself: on
// an organized image of a slanted plane, 3 mm of noise measures 3 mm; depth
// quantized in 5 mm steps without noise measures 0 (no widening).
TEST(Preprocess, PlaneNoiseFactorRemovesANoisyTableWhole) {
  const auto scene = [](double sigma) {
    pb::OrganizedCloud cloud;
    pb::Rng rng(8);
    for (int i = 0; i < 20000; ++i)  // table z = 1000 (seen from above), noise along z
      cloud.points.emplace_back(rng.uniform(-400, 400), rng.uniform(-400, 400), 1000 + rng.normal(0, sigma));
    for (int i = 0; i < 2000; ++i)  // a box 100 x 100 x 150 mm on it: its top and sides
      cloud.points.emplace_back(rng.uniform(-50, 50), rng.uniform(-50, 50), rng.uniform(850, 1000));
    cloud.width = static_cast<int>(cloud.points.size());
    cloud.height = 1;
    return cloud;
  };
  pb::PreprocessSettings s;
  s.voxel_mm = 0;
  s.plane_threshold_mm = 10;
  s.normal_radius_mm = 30;
  const auto table_left = [](const PointSet& ps) {
    int n = 0;
    for (const auto& p : ps.points) n += std::abs(p.x()) > 60 || std::abs(p.y()) > 60;
    return n;
  };
  const auto box_top = [](const PointSet& ps) {  // box points more than 60 mm above the table
    int n = 0;
    for (const auto& p : ps.points) n += std::abs(p.x()) < 50 && std::abs(p.y()) < 50 && p.z() < 940;
    return n;
  };
  const pb::OrganizedCloud noisy = scene(20);
  // The depth noise, from second differences of neighbouring pixels (here
  // independent draws on the table, then the box's).
  EXPECT_NEAR(pb::detail::depth_noise_sigma(noisy, 1), 20, 1.5);
  s.plane_noise_factor = 0;
  const PointSet fixed = pb::preprocess_scene(noisy, s, 1);
  s.plane_noise_factor = 2;
  const PointSet wide = pb::preprocess_scene(noisy, s, 1);
  EXPECT_GT(table_left(fixed), 10000);  // 62% of the table lies beyond 10 mm
  EXPECT_LT(table_left(wide), 2000);    // about 6% beyond 2 x 20 x 0.93 (the rays' median cos)
  EXPECT_GT(box_top(wide), 700);        // 60 of the box's 150 mm
  // Planes before the grid: the widening's median |cos| over about
  // plane_sample_points (here 1000) of the table's 20000 points: the same.
  s.planes_before_grid = true;
  s.plane_sample_points = 1000;
  const PointSet first = pb::preprocess_scene(noisy, s, 1);
  EXPECT_LT(table_left(first), 2000);
  EXPECT_GT(box_top(first), 700);
  s.planes_before_grid = false;
  s.plane_sample_points = 5000;
  // A clean table: the measured 1 mm x 2 is below the threshold.
  const pb::OrganizedCloud clean = scene(1);
  s.plane_noise_factor = 0;
  const PointSet a = pb::preprocess_scene(clean, s, 1);
  s.plane_noise_factor = 2;
  const PointSet b = pb::preprocess_scene(clean, s, 1);
  EXPECT_EQ(a.points, b.points);

  pb::OrganizedCloud image, steps;
  image.width = steps.width = 200;
  image.height = steps.height = 100;
  pb::Rng rng(9);
  for (int y = 0; y < 100; ++y)
    for (int x = 0; x < 200; ++x) {
      const double z = 1000 + 0.5 * x + 0.2 * y;
      image.points.emplace_back(x, y, z + rng.normal(0, 3));
      steps.points.emplace_back(x, y, 5 * std::floor(z / 5));
    }
  image.points[5].z() = std::numeric_limits<float>::quiet_NaN();  // invalid pixels are skipped
  EXPECT_NEAR(pb::detail::depth_noise_sigma(image), 3, 0.3);
  EXPECT_EQ(pb::detail::depth_noise_sigma(steps), 0);
  // depth_noise_exceeds decides sigma * factor > threshold as the median
  // does, on either side of the boundary and at it (ties: not above), at
  // every row step, and is false where sigma is 0 or undefined.
  for (const int row_step : {1, 2, 4, 7}) {
    const double sigma = pb::detail::depth_noise_sigma(image, row_step);
    for (const double factor : {1.0, 2.0, 2.5}) {
      const double at = sigma * factor;
      for (const double thr : {0.0, 0.5 * at, std::nextafter(at, 0.0), at, std::nextafter(at, 1e9), 2 * at})
        EXPECT_EQ(pb::detail::depth_noise_exceeds(image, factor, thr, row_step), sigma * factor > thr)
            << "row step " << row_step << ", factor " << factor << ", threshold " << thr;
    }
    EXPECT_FALSE(pb::detail::depth_noise_exceeds(steps, 2.0, 0.0, row_step));
  }
  pb::OrganizedCloud few = image;
  few.height = 1;
  few.points.resize(80);  // 78 triples: fewer than 100, sigma 0
  few.width = 80;
  EXPECT_EQ(pb::detail::depth_noise_sigma(few, 1), 0);
  EXPECT_FALSE(pb::detail::depth_noise_exceeds(few, 2.0, 0.0, 1));
}

// Mixed pixels at a depth edge: a wall at 1000 mm, a square 200 mm before
// it, and between them one column of pixels halfway (the mixed returns of a
// time-of-flight camera). The veil filter flags that column and the edge's
// last pixel on each side, nothing inside either surface, even with 1 mm of
// noise on 2 mm pixel spacing; off (0 deg) it flags nothing.
TEST(Preprocess, VeilFilterDropsMixedPixelsAndKeepsSurfaces) {
  const int W = 120, H = 80;
  const double f = 500;  // pixel spacing z / f: 2 mm at 1 m
  pb::Rng rng(3);
  pb::OrganizedCloud cloud;
  cloud.width = W;
  cloud.height = H;
  auto depth = [](int u) { return u < 60 ? 800.0 : u == 60 ? 900.0 : 1000.0; };
  for (int v = 0; v < H; ++v)
    for (int u = 0; u < W; ++u) {
      const double z = depth(u) + rng.normal(0, 1.0);
      cloud.points.emplace_back((u - W / 2 + 0.5) * z / f, (v - H / 2 + 0.5) * z / f, z);
    }
  cloud.points[5].z() = std::numeric_limits<float>::quiet_NaN();  // invalid pixels are skipped
  const std::vector<char> veil = pb::detail::veil_pixels(cloud, 10);
  int mixed = 0, edges = 0, inside = 0;
  for (int v = 0; v < H; ++v)
    for (int u = 0; u < W; ++u) {
      const char flag = veil[static_cast<size_t>(v) * W + u];
      if (u == 60) mixed += flag;
      else if (u == 59 || u == 61) edges += flag;
      else inside += flag;
    }
  EXPECT_EQ(mixed, H);
  EXPECT_EQ(edges, 2 * H);
  EXPECT_EQ(inside, 0);
  const std::vector<char> off = pb::detail::veil_pixels(cloud, 0);
  EXPECT_EQ(std::count(off.begin(), off.end(), 1), 0);

  // preprocess_scene drops them before the voxel grid: no point left
  // between the two surfaces.
  pb::PreprocessSettings s;
  s.voxel_mm = 0;
  s.remove_plane = false;
  s.normal_radius_mm = 10;
  auto between = [](const PointSet& ps) {
    int n = 0;
    for (const auto& p : ps.points) n += p.z() > 820 && p.z() < 980;
    return n;
  };
  EXPECT_EQ(between(pb::preprocess_scene(cloud, s, 1)), H);
  s.veil_angle_deg = 10;
  EXPECT_EQ(between(pb::preprocess_scene(cloud, s, 1)), 0);
}

// Normals by PCA in a radius: exact on a plane (zero curvature) and on a
// sphere (radial, curvature about r^2 / (8 R^2) of the neighbourhood),
// toward the viewpoint; points without 3 neighbours are dropped.
TEST(Normals, PlaneAndSphereNormalsAreExactAndFaceTheViewpoint) {
  PointSet plane;
  for (int x = -20; x <= 20; ++x)
    for (int y = -20; y <= 20; ++y) plane.points.emplace_back(5.f * x, 5.f * y, 600.f + 0.5f * x);
  plane.points.emplace_back(0.f, 0.f, 0.f);  // isolated: no neighbours within the radius
  pb::radius_normals(plane, 12.0);
  ASSERT_EQ(plane.size(), 41u * 41u);
  const Vec3f n_true = Vec3f(0.5f, 0, -5.f).normalized();  // facing the origin (negative z)
  for (size_t i = 0; i < plane.size(); ++i) {
    EXPECT_GT(plane.normals[i].dot(n_true), 0.99999f) << i;
    EXPECT_LT(plane.curvature[i], 1e-6f) << i;
  }
  PointSet sphere;
  pb::Rng rng(2);
  const Vec3f c(0, 0, 1000);
  for (int i = 0; i < 20000; ++i) {
    const pb::Vec3 d = pb::Vec3(rng.normal(), rng.normal(), rng.normal()).normalized();
    if (d.z() < -0.3) sphere.points.push_back(c + (d * 100).cast<float>());  // a cap facing the camera
  }
  pb::radius_normals(sphere, 15.0);
  for (size_t i = 0; i < sphere.size(); ++i) {
    const Vec3f radial = (sphere.points[i] - c).normalized();
    if (radial.z() > -0.5f) continue;  // away from the cap's rim (one-sided neighbourhoods)
    EXPECT_GT(sphere.normals[i].dot(radial), 0.995f) << i;  // outward = toward the camera here
  }
}

class TableScenePreprocess : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    mesh_ = new pb::Mesh(pbtest::make_l_block());
    scene_ = new pbtest::TableScene(pbtest::render_table_scene(*mesh_));
  }
  static void TearDownTestSuite() {
    delete scene_;
    delete mesh_;
  }
  static pb::Mesh* mesh_;
  static pbtest::TableScene* scene_;
};
pb::Mesh* TableScenePreprocess::mesh_ = nullptr;
pbtest::TableScene* TableScenePreprocess::scene_ = nullptr;

// Both orders: the grid before the planes (default) and the planes among
// the range-cut points before the grid (planes_before_grid).
TEST_F(TableScenePreprocess, RemovesTheTableKeepsTheObjectWithOrientedNormals) {
  const pb::OrganizedCloud cloud = pb::OrganizedCloud::from_depth(scene_->depth, scene_->K);
  PointSet grid_first;
  for (const bool first : {false, true}) {
  SCOPED_TRACE(first ? "planes before the grid" : "grid first");
  pb::PreprocessSettings s;
  s.planes_before_grid = first;
  const PointSet ps = pb::preprocess_scene(cloud, s, 5);
  // The same object left either way: the two counts within 15%.
  // The same object left either way (the two counts within 15%), but not
  // the same points: the grid's cells at the object's foot hold no table.
  if (!first) {
    grid_first = ps;
  } else {
    EXPECT_NEAR(static_cast<double>(ps.size()), static_cast<double>(grid_first.size()), 0.15 * grid_first.size());
    EXPECT_NE(ps.points, grid_first.points);
  }
  ASSERT_GT(ps.size(), 50u);
  ASSERT_TRUE(ps.has_normals());
  ASSERT_EQ(ps.curvature.size(), ps.size());
  EXPECT_TRUE(ps.pixel.empty()) << "a scene's points carry no pixel (preprocess.h)";
  EXPECT_EQ(ps.source_width, scene_->K.width);
  EXPECT_EQ(ps.source_height, scene_->K.height);
  // Every remaining point is on the object (within its box grown by the
  // voxel size and the noise), i.e. the table is gone.
  const pb::Pose T_model_cam = scene_->T_cam_model.inverse();
  Eigen::AlignedBox3f box = mesh_->bounds();
  box.min() -= Vec3f::Constant(12.f);
  box.max() += Vec3f::Constant(12.f);
  size_t on_object = 0;
  for (size_t i = 0; i < ps.size(); ++i) {
    const Vec3f pm = (T_model_cam.R * ps.points[i].cast<double>() + T_model_cam.t).cast<float>();
    on_object += box.contains(pm);
    EXPECT_NEAR(ps.normals[i].norm(), 1.0f, 1e-4f);
    EXPECT_LE(ps.normals[i].dot(ps.points[i]), 0.f) << "normal " << i << " faces away from the camera";
  }
  EXPECT_GE(on_object, ps.size() * 97 / 100);
  // Without plane removal the table stays: many more points.
  pb::PreprocessSettings keep = s;
  keep.remove_plane = false;
  EXPECT_GT(pb::preprocess_scene(cloud, keep, 5).size(), 3 * ps.size());
  // Range cut: everything beyond 1 mm of max range is cut.
  pb::PreprocessSettings near = s;
  near.max_range_mm = 300;
  EXPECT_EQ(pb::preprocess_scene(cloud, near, 5).size(), 0u);
  }
}

// pixel_stride n: the range cut reads every n-th pixel of every n-th row.
// Where a voxel is many pixels wide (640 x 480 at 50 degrees, 0.7 m away:
// 10 mm is about 10 pixels, as the warehouse's 20 mm at 2 m) the grid's
// cells are centroids of fewer samples of the same surfaces: about as many
// cells, each within a voxel of one from every pixel, the table still gone.
// (At 320 x 240, 5 pixels a voxel, stride 2 left 228 cells against 282; at
// 640 x 480, stride 4 left 233 against 333: both fail the count.)
TEST_F(TableScenePreprocess, PixelStrideKeepsTheObjectsCells) {
  pbtest::TableSceneOptions o;
  o.width = 640;
  o.height = 480;
  const pbtest::TableScene scene = pbtest::render_table_scene(*mesh_, o);
  const pb::OrganizedCloud cloud = pb::OrganizedCloud::from_depth(scene.depth, scene.K);
  pb::PreprocessSettings s;
  const PointSet all = pb::preprocess_scene(cloud, s, 5);
  s.pixel_stride = 2;
  const PointSet thin = pb::preprocess_scene(cloud, s, 5);
  ASSERT_GT(all.size(), 50u);
  EXPECT_NEAR(static_cast<double>(thin.size()), static_cast<double>(all.size()), 0.15 * all.size());
  EXPECT_NE(thin.points, all.points);
  EXPECT_EQ(thin.source_width, 640);
  EXPECT_EQ(thin.source_height, 480);
  ASSERT_TRUE(thin.has_normals());
  size_t near = 0;
  for (const Vec3f& p : thin.points) {
    float best = std::numeric_limits<float>::max();
    for (const Vec3f& q : all.points) best = std::min(best, (p - q).norm());
    near += best <= static_cast<float>(s.voxel_mm);
  }
  EXPECT_GE(near, thin.size() * 97 / 100);
  const pb::Pose T_model_cam = scene.T_cam_model.inverse();
  Eigen::AlignedBox3f box = mesh_->bounds();
  box.min() -= Vec3f::Constant(12.f);
  box.max() += Vec3f::Constant(12.f);
  size_t on_object = 0;
  for (const Vec3f& p : thin.points)
    on_object += box.contains((T_model_cam.R * p.cast<double>() + T_model_cam.t).cast<float>());
  EXPECT_GE(on_object, thin.size() * 97 / 100);
}

// every_nth_pixel: the pixels (x, y) with x and y multiples of n, in pixel
// order, and their drop flags alike.
TEST(Preprocess, EveryNthPixelThinsPointsAndFlagsAlike) {
  pb::OrganizedCloud c;
  c.width = 5;
  c.height = 3;
  std::vector<char> drop;
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 5; ++x) {
      c.points.emplace_back(static_cast<float>(x), static_cast<float>(y), 1000.f);
      drop.push_back(static_cast<char>(x == 4 && y == 2));
    }
  std::vector<char> flags = drop;
  const pb::OrganizedCloud t = pb::detail::every_nth_pixel(c, 2, flags);
  ASSERT_EQ(t.width, 3);
  ASSERT_EQ(t.height, 2);
  const std::vector<Vec3f> want = {{0, 0, 1000}, {2, 0, 1000}, {4, 0, 1000}, {0, 2, 1000}, {2, 2, 1000}, {4, 2, 1000}};
  EXPECT_EQ(t.points, want);
  EXPECT_EQ(flags, (std::vector<char>{0, 0, 0, 0, 0, 1}));
  std::vector<char> none;
  EXPECT_EQ(pb::detail::every_nth_pixel(c, 1, none).points, c.points);
  EXPECT_TRUE(none.empty());
}

TEST_F(TableScenePreprocess, SameBitsWithOneAndTwoThreads) {
  const pb::OrganizedCloud cloud = pb::OrganizedCloud::from_depth(scene_->depth, scene_->K);
  pb::PreprocessSettings s;
  const int saved = omp_get_max_threads();
  omp_set_num_threads(1);
  const PointSet a = pb::preprocess_scene(cloud, s, 9);
  omp_set_num_threads(2);
  const PointSet b = pb::preprocess_scene(cloud, s, 9);
  omp_set_num_threads(saved);
  ASSERT_EQ(a.size(), b.size());
  ASSERT_GT(a.size(), 0u);
  EXPECT_EQ(0, std::memcmp(a.points.data(), b.points.data(), a.size() * sizeof(Vec3f)));
  EXPECT_EQ(0, std::memcmp(a.normals.data(), b.normals.data(), a.size() * sizeof(Vec3f)));
  EXPECT_EQ(0, std::memcmp(a.curvature.data(), b.curvature.data(), a.size() * sizeof(float)));
  EXPECT_EQ(a.pixel, b.pixel);
}

TEST(Preprocess, ViewKeepsEverythingAndEmptyInputGivesEmptyOutput) {
  const pb::Mesh m = pbtest::make_l_block();
  pbtest::TableSceneOptions o;
  o.table = false;
  o.noise_mm = 0;
  const auto sc = pbtest::render_table_scene(m, o);
  const pb::OrganizedCloud cloud = pb::OrganizedCloud::from_depth(sc.depth, sc.K);
  pb::PreprocessSettings s;
  s.max_range_mm = 200;  // preprocess_view ignores the scene's range cut
  const PointSet v = pb::preprocess_view(cloud, s, 1);
  EXPECT_GT(v.size(), 50u);
  EXPECT_TRUE(v.has_normals());

  pb::DepthImage empty(64, 48);
  const pb::Intrinsics K = pb::Intrinsics::from_fov(64, 48, 50, 40);
  const pb::OrganizedCloud ec = pb::OrganizedCloud::from_depth(empty, K);
  EXPECT_TRUE(pb::preprocess_scene(ec, pb::PreprocessSettings{}, 1).empty());
  EXPECT_TRUE(pb::preprocess_view(ec, pb::PreprocessSettings{}, 1).empty());
  // A handful of isolated points: no normal can be estimated, so none survive.
  pb::DepthImage sparse(64, 48);
  sparse.at(5, 5) = 800;
  sparse.at(40, 30) = 900;
  EXPECT_TRUE(pb::preprocess_scene(pb::OrganizedCloud::from_depth(sparse, K), pb::PreprocessSettings{}, 1).empty());
}

TEST(Verify, PointIndexMatchesBruteForceAndCountsInliers) {
  pb::Rng rng(11);
  std::vector<Vec3f> pts;
  for (int i = 0; i < 500; ++i)
    pts.emplace_back(rng.uniform(-100, 100), rng.uniform(-100, 100), rng.uniform(400, 600));
  const pb::PointIndex index(pts);
  EXPECT_EQ(index.size(), 500u);
  for (int q = 0; q < 50; ++q) {
    const Vec3f p(rng.uniform(-120, 120), rng.uniform(-120, 120), rng.uniform(380, 620));
    int best = -1;
    float bd = 1e30f;
    std::vector<int> within;
    for (int i = 0; i < 500; ++i) {
      const float d = (pts[i] - p).squaredNorm();
      if (d < bd) bd = d, best = i;
      if (d <= 30.f * 30.f) within.push_back(i);
    }
    float d2;
    EXPECT_EQ(index.nearest(p, &d2), best);
    EXPECT_NEAR(d2, bd, 1e-2f);
    std::vector<int> r = index.radius(p, 30.f);
    std::sort(r.begin(), r.end());
    EXPECT_EQ(r, within);
  }
  // Inliers: the cloud against itself under the identity, then shifted.
  EXPECT_EQ(pb::count_inliers(pts, pb::Pose::identity(), index, 1.0), 500);
  pb::Pose far;
  far.t = pb::Vec3(0, 0, 1000);
  EXPECT_EQ(pb::count_inliers(pts, far, index, 10.0), 0);
  pb::Pose small;
  small.t = pb::Vec3(0.5, 0, 0);
  EXPECT_EQ(pb::count_inliers(pts, small, index, 1.0), 500);

  const pb::PointIndex empty(std::vector<Vec3f>{});
  float d2 = 0;
  EXPECT_EQ(empty.nearest(Vec3f(0, 0, 0), &d2), -1);
  EXPECT_TRUE(empty.radius(Vec3f(0, 0, 0), 10).empty());
  EXPECT_EQ(pb::count_inliers(pts, pb::Pose::identity(), empty, 10.0), 0);
}

}  // namespace
