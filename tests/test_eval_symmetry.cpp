// The BOP symmetry set: sizes, order, the identity first, rotations about the
// axis by i * 2 pi / n, translations -R * offset + offset, and bad input.
#include <gtest/gtest.h>

#include <cmath>

#include "core/error.h"
#include "core/rotation.h"
#include "eval/symmetry.h"

using namespace pb;

namespace {

Mat4 rot_z_180() {
  Mat4 T = Mat4::Identity();
  T.block<3, 3>(0, 0) = axis_angle(Vec3::UnitZ(), M_PI);
  return T;
}

}  // namespace

TEST(EvalSymmetry, NoSymmetryIsTheIdentityAlone) {
  const std::vector<Pose> s = symmetry_transformations(std::vector<Mat4>{}, std::vector<ContinuousSymmetry>{});
  ASSERT_EQ(s.size(), 1u);
  EXPECT_TRUE(s[0].R.isApprox(Mat3::Identity(), 0));
  EXPECT_EQ(s[0].t, Vec3::Zero());
}

TEST(EvalSymmetry, StepCountIsCeilPiOverStep) {
  EXPECT_EQ(continuous_symmetry_steps(0.01), 315);  // ceil(314.159...)
  EXPECT_EQ(continuous_symmetry_steps(0.5), 7);     // ceil(6.28...)
  EXPECT_EQ(continuous_symmetry_steps(M_PI / 4), 4);
  EXPECT_THROW(continuous_symmetry_steps(0.0), std::invalid_argument);
  EXPECT_THROW(continuous_symmetry_steps(-1.0), std::invalid_argument);
}

TEST(EvalSymmetry, DiscreteOnlyIsIdentityPlusTheList) {
  Mat4 D = rot_z_180();
  D(0, 3) = 5.0;
  const std::vector<Pose> s = symmetry_transformations({D}, {});
  ASSERT_EQ(s.size(), 2u);
  EXPECT_EQ(s[0].R, Mat3::Identity());
  EXPECT_TRUE(s[1].R.isApprox(D.block<3, 3>(0, 0), 1e-15));
  EXPECT_EQ(s[1].t, Vec3(5, 0, 0));
}

TEST(EvalSymmetry, ContinuousAboutZIsEvenlySpacedRotations) {
  ContinuousSymmetry c;
  c.axis = Vec3(0, 0, 2.0);  // not unit: normalized like the toolkit
  const std::vector<Pose> s = symmetry_transformations({}, {c});
  ASSERT_EQ(s.size(), 315u);
  const double step = 2 * M_PI / 315;
  for (size_t i = 0; i < s.size(); ++i) {
    const Mat3 expected = axis_angle(Vec3::UnitZ(), i * step);
    EXPECT_TRUE(s[i].R.isApprox(expected, 1e-12)) << i;
    EXPECT_EQ(s[i].t, Vec3::Zero()) << i;  // offset 0: exactly zero translation
    EXPECT_NEAR(s[i].R(2, 2), 1.0, 1e-15);  // the axis is fixed
  }
  EXPECT_EQ(s[0].R, Mat3::Identity());
}

TEST(EvalSymmetry, ContinuousWithOffsetFixesTheAxisLine) {
  ContinuousSymmetry c;
  c.axis = Vec3(1, 1, 0).normalized();
  c.offset = Vec3(10, -20, 30);
  SymmetryOptions opt;
  opt.max_sym_disc_step = 0.5;  // 7 steps
  const std::vector<Pose> s = symmetry_transformations({}, {c}, opt);
  ASSERT_EQ(s.size(), 7u);
  for (const Pose& S : s) {
    // Every point of the axis line maps to itself; t = -R o + o.
    for (double lambda : {-50.0, 0.0, 80.0}) {
      const Vec3 p = c.offset + lambda * c.axis;
      EXPECT_LT((S * p - p).norm(), 1e-12);
    }
    EXPECT_LT((S.t - (-S.R * c.offset + c.offset)).norm(), 1e-12);
  }
  // A point off the axis moves by 2 r sin(angle / 2) at step 1.
  const Vec3 off = c.offset + Vec3(0, 0, 40);  // 40 mm from the axis
  const double expected = 2 * 40 * std::sin(M_PI / 7);
  EXPECT_NEAR((s[1] * off - off).norm(), expected, 1e-12);
}

TEST(EvalSymmetry, DiscreteTimesContinuousInToolkitOrder) {
  ContinuousSymmetry c;  // about z
  Mat4 D = Mat4::Identity();  // flip: 180 degrees about x, with a translation
  D.block<3, 3>(0, 0) = axis_angle(Vec3::UnitX(), M_PI);
  D(2, 3) = 3.0;
  SymmetryOptions opt;
  opt.max_sym_disc_step = 0.5;
  const std::vector<Pose> s = symmetry_transformations({D}, {c}, opt);
  ASSERT_EQ(s.size(), 14u);
  const double step = 2 * M_PI / 7;
  for (int i = 0; i < 7; ++i) {
    const Mat3 C = axis_angle(Vec3::UnitZ(), i * step);
    EXPECT_TRUE(s[i].R.isApprox(C, 1e-12));  // C_i * identity
    EXPECT_LT(s[i].t.norm(), 1e-15);
    // C_i * D: R = C D.R, t = C D.t + 0
    EXPECT_TRUE(s[7 + i].R.isApprox(C * D.block<3, 3>(0, 0), 1e-12));
    EXPECT_LT((s[7 + i].t - C * Vec3(0, 0, 3)).norm(), 1e-12);
  }
}

TEST(EvalSymmetry, TwoContinuousSymmetriesAreConcatenatedNotCombined) {
  ContinuousSymmetry a, b;
  b.axis = Vec3::UnitX();
  SymmetryOptions opt;
  opt.max_sym_disc_step = 0.5;
  EXPECT_EQ(symmetry_transformations({}, {a, b}, opt).size(), 14u);
  EXPECT_EQ(symmetry_transformations({rot_z_180()}, {a, b}, opt).size(), 28u);
}

TEST(EvalSymmetry, FromModelInfo) {
  ModelInfo info;
  info.symmetries_discrete = {rot_z_180()};
  EXPECT_EQ(symmetry_transformations(info).size(), 2u);
  info.symmetries_continuous.push_back({});
  EXPECT_EQ(symmetry_transformations(info).size(), 630u);
}

TEST(EvalSymmetry, BadInputNamesTheField) {
  ContinuousSymmetry c;
  c.axis = Vec3::Zero();
  try {
    symmetry_transformations({}, {ContinuousSymmetry{}, c});
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "symmetries_continuous[1].axis");
  }
  Mat4 D = Mat4::Identity();
  D(0, 0) = std::nan("");
  try {
    symmetry_transformations({D}, {});
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "symmetries_discrete[0]");
  }
}
