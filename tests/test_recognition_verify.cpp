// Verification by the depth image (verify.score: visibility, issue 9): a
// hypothesis whose model lies in space the sensor saw through scores below
// the correct one, even where the thesis's inlier count prefers it.
//
// The scene, ray-cast analytically (camera at the origin, OpenCV frame,
// mm): a wall at z = 1000; a 100 mm cube whose front face is at z = 800,
// centred on the optical axis; a plate at z = 700 that hides most of that
// face (x < 30 mm). The model: the cube's six faces sampled every 10 mm,
// normals outward.
//   correct: the cube where it is; only a 20 mm strip of its front face is
//            seen, so it has few inliers;
//   wrong:   the cube 300 mm to the right with its back face on the wall:
//            the whole back face lies on scene points (many inliers), but
//            its front face floats 100 mm in front of the wall, where the
//            sensor saw the wall: free space.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "recognition/verify/verify.h"

namespace {

pb::Intrinsics camera() {
  pb::Intrinsics K;
  K.fx = K.fy = 500;
  K.cx = 320;
  K.cy = 240;
  K.width = 640;
  K.height = 480;
  return K;
}

// Nearest surface along each pixel's ray: plate, cube front face, wall.
pb::DepthImage render(const pb::Intrinsics& K, bool plate = true) {
  pb::DepthImage d;
  d.width = K.width;
  d.height = K.height;
  d.z.assign(static_cast<size_t>(K.width * K.height), 0.f);
  for (int v = 0; v < K.height; ++v)
    for (int u = 0; u < K.width; ++u) {
      const double rx = (u - K.cx) / K.fx, ry = (v - K.cy) / K.fy;
      auto hits = [&](double z, double x0, double x1, double y0, double y1) {
        const double x = rx * z, y = ry * z;
        return x >= x0 && x <= x1 && y >= y0 && y <= y1;
      };
      float z = 1000.f;                                         // wall
      if (hits(800, -50, 50, -50, 50)) z = 800.f;                // cube front face
      if (plate && hits(700, -80, 30 * 0.7 / 0.8, -80, 80)) z = 700.f;  // plate: hides x < 30 mm at the face
      d.z[static_cast<size_t>(v * K.width + u)] = z;
    }
  return d;
}

// The cube's faces, every 10 mm, centred on the model origin, normals out.
pb::PointSet cube_model() {
  pb::PointSet m;
  for (int axis = 0; axis < 3; ++axis)
    for (int sign : {-1, 1})
      for (int a = -50; a <= 50; a += 10)
        for (int b = -50; b <= 50; b += 10) {
          pb::Vec3f p, n = pb::Vec3f::Zero();
          p[axis] = 50.f * sign;
          p[(axis + 1) % 3] = static_cast<float>(a);
          p[(axis + 2) % 3] = static_cast<float>(b);
          n[axis] = static_cast<float>(sign);
          m.points.push_back(p);
          m.normals.push_back(n);
        }
  return m;
}

std::vector<pb::Vec3f> scene_points(const pb::DepthImage& d, const pb::Intrinsics& K) {
  std::vector<pb::Vec3f> pts;
  for (int v = 0; v < d.height; v += 2)
    for (int u = 0; u < d.width; u += 2) {
      const float z = d.z[static_cast<size_t>(v * d.width + u)];
      pts.emplace_back(static_cast<float>((u - K.cx) * z / K.fx), static_cast<float>((v - K.cy) * z / K.fy), z);
    }
  return pts;
}

pb::Pose at(double x, double z) {
  pb::Pose T;
  T.t = pb::Vec3(x, 0, z);
  return T;
}

TEST(VerifyVisibility, AFreeSpaceViolatingHypothesisScoresBelowTheCorrectOne) {
  const pb::Intrinsics K = camera();
  const pb::DepthImage depth = render(K);
  const pb::PointSet model = cube_model();
  const pb::PointIndex scene(scene_points(depth, K));
  const double tol = 10;
  const pb::Pose correct = at(0, 850);  // front face at 800
  const pb::Pose wrong = at(300, 950);  // back face on the wall at 1000, front face at 900

  // The thesis's score prefers the wrong pose: its back face lies on the wall.
  const int inliers_correct = pb::count_inliers(model.points, correct, scene, tol);
  const int inliers_wrong = pb::count_inliers(model.points, wrong, scene, tol);
  EXPECT_GT(inliers_wrong, inliers_correct);

  const pb::DepthEvidence c = pb::depth_evidence(model, correct, depth, K, tol);
  const pb::DepthEvidence w = pb::depth_evidence(model, wrong, depth, K, tol);
  // Correct: the seen strip supports it, the hidden part is occluded, nothing in free space.
  EXPECT_GT(c.supported, 0);
  EXPECT_EQ(c.violating, 0);
  EXPECT_GT(c.occluded, c.supported);  // most of it is behind the plate
  // Wrong: its front face (121 points facing the camera) is in free space; the
  // back face faces away and counts in nothing.
  EXPECT_GE(w.violating, 121);
  EXPECT_LT(w.supported, w.violating);
  EXPECT_GT(c.score(1.0), w.score(1.0));
  std::printf("inliers correct %d wrong %d; visibility correct %d/%d/%d wrong %d/%d/%d (supported/violating/occluded)\n",
              inliers_correct, inliers_wrong, c.supported, c.violating, c.occluded, w.supported, w.violating,
              w.occluded);
}

TEST(VerifyVisibility, PointsOffTheImageOrWithoutDepthCountInNothing) {
  const pb::Intrinsics K = camera();
  pb::DepthImage depth = render(K);
  const pb::PointSet model = cube_model();
  // Far to the side: every point projects outside the image.
  const pb::DepthEvidence off = pb::depth_evidence(model, at(5000, 900), depth, K, 10);
  EXPECT_EQ(off.supported + off.violating + off.occluded, 0);
  // No depth anywhere (NaN and 0): unknown, not free space.
  for (size_t i = 0; i < depth.z.size(); ++i) depth.z[i] = (i % 2) ? 0.f : std::nanf("");
  const pb::DepthEvidence none = pb::depth_evidence(model, at(0, 850), depth, K, 10);
  EXPECT_EQ(none.supported + none.violating + none.occluded, 0);
  // A depth image of another size than the intrinsics is a caller's error.
  depth.width = 10;
  EXPECT_THROW(pb::depth_evidence(model, at(0, 850), depth, K, 10), std::invalid_argument);
}

// A pose sunk into a surface: the cube 300 mm to the right with its front
// face in the wall's plane. depth_evidence sees its front face on the wall
// and the rest behind it (and the first row of the side face it shows the
// camera on the wall too): it scores at least as well as the true cube (no
// plate here). Its outline does not: around the true cube the wall lies
// 200 mm behind the face (the outline stands out); around the sunk one it
// continues the face, except along that side face, whose hidden part
// reaches 100 mm behind the wall (the wall is nearer there).
TEST(VerifyOutline, APoseSunkIntoAWallHasAContinuousOutlineTheTrueOneAStep) {
  const pb::Intrinsics K = camera();
  const pb::DepthImage depth = render(K, /*plate=*/false);
  const pb::PointSet model = cube_model();
  const pb::Pose truth = at(0, 850), sunk = at(300, 1050);
  const double tol = 10, spacing = 10;
  const pb::DepthEvidence et = pb::depth_evidence(model, truth, depth, K, tol);
  const pb::DepthEvidence es = pb::depth_evidence(model, sunk, depth, K, tol);
  EXPECT_EQ(et.supported, 121);
  EXPECT_EQ(et.violating, 0);
  EXPECT_GE(es.supported, 121);
  EXPECT_EQ(es.violating, 0);
  EXPECT_GE(es.score(1.0), et.score(1.0));

  const pb::OutlineEvidence ot = pb::outline_evidence(model, truth, depth, K, spacing, tol, 3);
  const pb::OutlineEvidence os = pb::outline_evidence(model, sunk, depth, K, spacing, tol, 3);
  // The front face spans 62 px at 800 mm (50 at 1000): an outline of about 4 x that.
  EXPECT_GT(ot.probed, 150);
  EXPECT_GT(os.probed, 150);
  EXPECT_EQ(ot.continuous, 0);
  EXPECT_EQ(ot.nearer, 0);
  EXPECT_EQ(ot.standing_fraction(), 1.0);
  EXPECT_GT(os.continuous, os.probed / 2);
  EXPECT_LT(os.standing_fraction(), 0.4);

  pb::VerifySettings v;
  v.inlier_threshold_mm = tol;
  v.outline_weight = 1.0;
  EXPECT_EQ(pb::visibility_score(model, truth, depth, K, v, spacing), 121.0);
  EXPECT_NEAR(pb::visibility_score(model, sunk, depth, K, v, spacing), es.score(1.0) * os.standing_fraction(), 1e-9);
  EXPECT_LT(pb::visibility_score(model, sunk, depth, K, v, spacing), 0.5 * 121.0);
  v.outline_weight = 0.0;  // off: depth_evidence's score alone
  EXPECT_EQ(pb::visibility_score(model, sunk, depth, K, v, spacing), es.score(1.0));
}

TEST(VerifyOutline, ProbesOffTheImageOrWithoutDepthCountInNothing) {
  const pb::Intrinsics K = camera();
  pb::DepthImage depth = render(K, false);
  const pb::PointSet model = cube_model();
  EXPECT_EQ(pb::outline_evidence(model, at(5000, 900), depth, K, 10, 10, 3).probed, 0);
  for (float& z : depth.z) z = 0.f;
  EXPECT_EQ(pb::outline_evidence(model, at(0, 850), depth, K, 10, 10, 3).probed, 0);
  depth.width = 10;
  EXPECT_THROW(pb::outline_evidence(model, at(0, 850), depth, K, 10, 10, 3), std::invalid_argument);
}

}  // namespace
