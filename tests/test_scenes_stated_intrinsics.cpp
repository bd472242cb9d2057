// A scene set whose files state other intrinsics than the optics that
// rendered it (scene config `stated_intrinsics`): the same depth, the stated
// camera matrix, the ground truth's translation mapped so that the model
// still projects where it was rendered, its rotation kept; bad values are
// InputErrors naming the file and the field.
#include <gtest/gtest.h>

#include <string>

#include "core/error.h"
#include "core/yaml.h"
#include "scenes/generator.h"
#include "scenes/scene_config.h"

using namespace pb;

namespace {

// The real Kinect v2's optics (fx = fy = 365) under the Kinect One profile.
const char* kKinect = R"(
scenario: table
scene_id: 1
seed: 5
images: 2
sensor: {name: kinect_one, fx: 365, fy: 365}
target: ls5
distractors: {pool: [milk_carton, box_small], count: [2, 3]}
)";

SceneSettings settings_from(const std::string& yaml) {
  SceneSettings s = parse_scene_settings(YamlNode::load_string(yaml, "kinect.yaml"));
  s.name = "test";
  return s;
}

}  // namespace

TEST(SceneStatedIntrinsics, BuiltInSensorWithOtherOpticsKeepsItsNoiseAndRanges) {
  const SceneSettings s = settings_from(kKinect);
  EXPECT_EQ(s.sensor.name, "kinect_one");
  EXPECT_EQ(s.noise.model, "tof");
  EXPECT_EQ(s.sensor.K.width, 512);
  EXPECT_EQ(s.sensor.K.height, 424);
  EXPECT_DOUBLE_EQ(s.sensor.K.fx, 365);
  EXPECT_DOUBLE_EQ(s.sensor.K.cx, 255.5);
  EXPECT_DOUBLE_EQ(s.sensor.max_range_mm, 4500);
  EXPECT_FALSE(s.has_stated_intrinsics);
  EXPECT_EQ(&dataset_intrinsics(s), &s.sensor.K);
}

TEST(SceneStatedIntrinsics, FilesStateTheirIntrinsicsAndTheModelStillProjectsWhereRendered) {
  const SceneSettings plain = settings_from(kKinect);
  const SceneSettings stated = settings_from(std::string(kKinect) + "stated_intrinsics: {hfov_deg: 57, vfov_deg: 43}\n");
  ASSERT_TRUE(stated.has_stated_intrinsics);
  const Intrinsics table21 = Intrinsics::from_fov(512, 424, 57, 43);
  EXPECT_DOUBLE_EQ(stated.stated_intrinsics.fx, table21.fx);
  EXPECT_DOUBLE_EQ(stated.stated_intrinsics.fy, table21.fy);
  SceneGenerator a(plain), b(stated);
  for (int im = 0; im < 2; ++im) {
    const GeneratedImage p = a.generate(im), q = b.generate(im);
    EXPECT_EQ(p.depth.z, q.depth.z) << "im " << im;  // the same frame
    EXPECT_DOUBLE_EQ(q.info.K.fx, table21.fx);
    ASSERT_EQ(p.info.gt.size(), q.info.gt.size());
    for (size_t k = 0; k < p.info.gt.size(); ++k) {
      const Pose& T = p.info.gt[k].T_cam_model;
      const Pose& S = q.info.gt[k].T_cam_model;
      EXPECT_TRUE(S.R.isApprox(T.R, 1e-12));
      EXPECT_DOUBLE_EQ(S.t.z(), T.t.z());
      // Squashed across the view: x by 365 / 471.6, y by 365 / 538.4.
      EXPECT_NEAR(S.t.x(), T.t.x() * 365.0 / table21.fx, 1e-6);
      EXPECT_NEAR(S.t.y(), T.t.y() * 365.0 / table21.fy, 1e-6);
      const Eigen::Vector2d uv_true = p.info.K.project(T.t), uv_read = q.info.K.project(S.t);
      EXPECT_NEAR((uv_true - uv_read).norm(), 0.0, 1e-6) << "im " << im << " object " << k;
    }
  }
}

TEST(SceneStatedIntrinsics, BadStatedIntrinsicsNameTheField) {
  struct Case {
    const char* yaml;
    const char* field;
  };
  for (const Case& c : {Case{"stated_intrinsics: {hfov_deg: 57}\n", "stated_intrinsics.vfov_deg"},
                        Case{"stated_intrinsics: {fx: -3, fy: 365}\n", "stated_intrinsics.fx"},
                        Case{"stated_intrinsics: {width: 640}\n", "stated_intrinsics"},
                        Case{"stated_intrinsics: {fov: 57}\n", "stated_intrinsics.fov"}}) {
    try {
      settings_from(std::string(kKinect) + c.yaml);
      ADD_FAILURE() << "no InputError for " << c.yaml;
    } catch (const InputError& e) {
      EXPECT_EQ(e.file(), "kinect.yaml") << c.yaml;
      EXPECT_NE(std::string(e.what()).find(c.field), std::string::npos) << e.what();
    }
  }
}
