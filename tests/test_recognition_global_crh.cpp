// Camera Roll Histogram: a view rolled by a known angle about the camera axis
// is recovered within 4 degrees (pcl::CRHEstimation + our phase correlation,
// cross-checked against pcl::CRHAlignment).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "recognition/global/internal.h"
#include "test_recognition_global_util.h"

namespace pb {
namespace {

using namespace testing_global;

double angle_diff_deg(double a_rad, double b_deg) {
  double d = std::fmod(a_rad * 180 / M_PI - b_deg, 360.0);
  if (d < -180) d += 360;
  if (d > 180) d -= 360;
  return std::abs(d);
}

PointSet rotated(const PointSet& in, const Mat3& R) {
  PointSet out = in;
  const Eigen::Matrix3f Rf = R.cast<float>();
  for (auto& p : out.points) p = Rf * p;
  for (auto& n : out.normals) n = Rf * n;
  return out;
}

Vec3f centroid(const PointSet& c) {
  Eigen::Vector3d s = Eigen::Vector3d::Zero();
  for (const auto& p : c.points) s += p.cast<double>();
  return (s / static_cast<double>(c.size())).cast<float>();
}

class GlobalCrh : public ::testing::Test {
 protected:
  void SetUp() override {
    mesh_ = asymmetric_object();
    K_ = synthetic_camera();
    T_ = camera_pose(30, 30, 0, 700);
    view_ = preprocess_view(render_cloud(mesh_, T_, K_, 1.0, 1), s_.preprocess, 2);
    ASSERT_GT(view_.size(), 200u);
    ASSERT_TRUE(view_.has_normals());
  }
  Mesh mesh_;
  Intrinsics K_;
  Pose T_;
  PointSet view_;
  RecognitionSettings s_;
};

// The cloud rotated about the ray through its centroid (the camera axis of
// the object): the top CRH peak is the angle, and PCL's CRHAlignment agrees.
TEST_F(GlobalCrh, RolledCloudRecovered) {
  const Vec3f c = centroid(view_);
  const Vec3f axis = c.normalized();
  const auto V = global::crh_spectrum(view_, axis);
  ASSERT_EQ(V.size(), 90u);
  for (double deg : {40.0, 100.0, 250.0, 7.0, 181.0, 333.0}) {
    const Mat3 Ra = axis_angle(axis.cast<double>(), deg * M_PI / 180);
    const PointSet rolled = rotated(view_, Ra);
    const auto S = global::crh_spectrum(rolled, axis);
    const auto peaks = global::crh_roll_peaks(S, V, s_.global);
    const auto pcl_peaks = global::pcl_crh_roll_peaks(S, V);
    ASSERT_FALSE(peaks.empty());
    ASSERT_FALSE(pcl_peaks.empty());
    const double err = angle_diff_deg(peaks[0], deg), pcl_err = angle_diff_deg(pcl_peaks[0], deg);
    const Mat3 R = global::roll_rotation(axis, axis, peaks[0]);
    const double rot_err = rotation_angle_deg(R, Ra);
    std::printf("roll %6.1f deg: CRH %.2f deg off (PCL CRHAlignment %.2f), rotation error %.2f deg, %zu peaks\n", deg,
                err, pcl_err, rot_err, peaks.size());
    EXPECT_LT(err, 4.0) << deg;
    EXPECT_LT(pcl_err, 4.0) << deg;
    EXPECT_LT(rot_err, 4.0) << deg;
  }
}

// Re-rendered with the camera rolled about its optical axis (new pixels,
// voxels and noise): the method's path (CVFH regions, axes from the mean
// normals, CRH roll) recovers the rotation within 4 degrees.
TEST_F(GlobalCrh, RerenderedRollRecoveredThroughRegions) {
  const auto view_sigs = global::cvfh_signatures(view_, s_.global);
  ASSERT_FALSE(view_sigs.empty());
  for (double deg : {40.0, 100.0, 250.0}) {
    const Mat3 Rz = axis_angle(Vec3::UnitZ(), deg * M_PI / 180);
    Pose roll;
    roll.R = Rz;
    const PointSet scene = preprocess_view(render_cloud(mesh_, roll * T_, K_, 1.0, 10 + deg), s_.preprocess, 3);
    const auto scene_sigs = global::cvfh_signatures(scene, s_.global);
    ASSERT_FALSE(scene_sigs.empty());
    // The largest region of the scene and its counterpart in the view (the
    // nearest centroid after the true roll).
    const global::Signature& ss = scene_sigs.front();
    size_t best = 0;
    double best_d = 1e9;
    for (size_t j = 0; j < view_sigs.size(); ++j) {
      const double d = (Rz.cast<float>() * view_sigs[j].centroid - ss.centroid).norm();
      if (d < best_d) best_d = d, best = j;
    }
    const global::Signature& vs = view_sigs[best];
    ASSERT_LT(best_d, 20.0);
    const auto S = global::crh_spectrum(scene, ss.axis), V = global::crh_spectrum(view_, vs.axis);
    const auto peaks = global::crh_roll_peaks(S, V, s_.global);
    ASSERT_FALSE(peaks.empty());
    double best_err = 1e9;
    for (double th : peaks) best_err = std::min(best_err, rotation_angle_deg(global::roll_rotation(vs.axis, ss.axis, th), Rz));
    const double top_err = rotation_angle_deg(global::roll_rotation(vs.axis, ss.axis, peaks[0]), Rz);
    // Whole-cloud CRH about the centroid rays (ESF's path).
    const Vec3f cv = centroid(view_).normalized(), cs = centroid(scene).normalized();
    const auto pk2 = global::crh_roll_peaks(global::crh_spectrum(scene, cs), global::crh_spectrum(view_, cv), s_.global);
    ASSERT_FALSE(pk2.empty());
    const double centroid_err = rotation_angle_deg(global::roll_rotation(cv, cs, pk2[0]), Rz);
    std::printf("camera roll %6.1f deg: region axes: top peak %.2f deg, best of %zu peaks %.2f deg; centroid axes: %.2f deg\n",
                deg, top_err, peaks.size(), best_err, centroid_err);
    EXPECT_LT(top_err, 4.0) << deg;
    EXPECT_LT(centroid_err, 4.0) << deg;
  }
}

TEST(GlobalCrhUpright, UprightRollKeepsCameraUp) {
  // Same axis: no roll. An axis tilted sideways: the roll keeps -y up.
  const Vec3f a(0.1f, 0.2f, 1.f);
  EXPECT_NEAR(global::upright_roll(a.normalized(), a.normalized()), 0.0, 1e-9);
  const Vec3f b(0.3f, -0.1f, 1.f);
  const Mat3 R = global::roll_rotation(a.normalized(), b.normalized(), global::upright_roll(a.normalized(), b.normalized()));
  EXPECT_LT((R * a.normalized().cast<double>() - b.normalized().cast<double>()).norm(), 1e-6);
  // The image's up stays nearly up for small axis changes.
  EXPECT_GT((R * Vec3(0, -1, 0)).dot(Vec3(0, -1, 0)), 0.95);
}

}  // namespace
}  // namespace pb
