// The milk carton judged two ways (Table 4.5) by eval's thesis_judge: over
// the model's own symmetry set (models/models.yaml: the half turn about its
// vertical axis) and over the thesis's "faces on faces" set that
// configs/thesis/table_4_5.yaml declares as judgements.faces (the 8
// rotations of the 70 x 70 x 195 mm body about its centre (0, 0, -22.5) mm).
// A carton turned 90 degrees about z, or upside down, is wrong under the
// first and correct under the second; a pose 60 mm off is wrong under both.
#include <gtest/gtest.h>

#include <cmath>

#include "core/rotation.h"
#include "core/yaml.h"
#include "eval/errors.h"
#include "eval/symmetry.h"
#include "io/symmetry_yaml.h"
#include "models/registry.h"

namespace {

const pb::Vec3 kCentre(0, 0, -22.5);  // the carton body's centre, model frame (mm)

// The faces set as the config declares it (judgements.faces), read with the
// same reader as models.yaml's symmetries.
std::vector<pb::Pose> faces_from_config() {
  const pb::YamlNode root =
      pb::YamlNode::load_file(std::string(POSEBENCH_SOURCE_DIR) + "/configs/thesis/table_4_5.yaml");
  std::vector<pb::Mat4> discrete;
  std::vector<pb::ContinuousSymmetry> continuous;
  pb::read_symmetries(root["judgements"]["faces"], discrete, continuous);
  return pb::symmetry_transformations(discrete, continuous);
}

std::vector<pb::Pose> carton_model_symmetries() {
  const pb::ModelRegistry reg = pb::ModelRegistry::load(std::string(POSEBENCH_SOURCE_DIR) + "/models/models.yaml");
  const pb::ModelSpec& carton = reg.spec("milk_carton");
  return pb::symmetry_transformations(carton.symmetries_discrete, carton.symmetries_continuous);
}

// x -> R x + (c - R c): R about the body's centre.
pb::Pose about_centre(const pb::Mat3& R) {
  pb::Pose S;
  S.R = R;
  S.t = kCentre - R * kCentre;
  return S;
}

const pb::ThesisThresholds kTable{50.0, 0.05};

TEST(EvalJudgements, FacesSetIsTheEightRotationsOfTheCartonBody) {
  const auto faces = faces_from_config();
  ASSERT_EQ(faces.size(), 8u);
  const pb::Mat3 flip = pb::Vec3(1, -1, -1).asDiagonal();
  for (int k = 0; k < 4; ++k)
    for (const pb::Mat3& F : {pb::Mat3(pb::Mat3::Identity()), flip}) {
      const pb::Pose want = about_centre(pb::axis_angle(pb::Vec3::UnitZ(), k * M_PI / 2) * F);
      int found = 0;
      for (const auto& S : faces)
        found += (S.R - want.R).norm() < 1e-9 && (S.t - want.t).norm() < 1e-9;
      EXPECT_EQ(found, 1) << "k = " << k << ", flipped = " << (F != pb::Mat3::Identity());
    }
}

TEST(EvalJudgements, CartonTurnedOrUpsideDownIsWrongUnderItsOwnSetAndCorrectUnderFaces) {
  const auto model = carton_model_symmetries();
  ASSERT_EQ(model.size(), 2u);  // identity and the half turn about z
  const auto faces = faces_from_config();

  pb::Pose gt;
  gt.R = pb::axis_angle(pb::Vec3(0.3, -1, 0.2), 0.7);
  gt.t = pb::Vec3(40, -20, 800);
  const pb::Pose turned = gt * about_centre(pb::axis_angle(pb::Vec3::UnitZ(), M_PI / 2));
  const pb::Pose upside_down = gt * about_centre(pb::Vec3(1, -1, -1).asDiagonal());
  pb::Pose off = gt;
  off.t += pb::Vec3(60, 0, 0);

  EXPECT_TRUE(pb::thesis_judge(gt, gt, model, kTable).correct);
  EXPECT_TRUE(pb::thesis_judge(gt, gt, faces, kTable).correct);

  const auto turned_model = pb::thesis_judge(turned, gt, model, kTable);
  const auto turned_faces = pb::thesis_judge(turned, gt, faces, kTable);
  EXPECT_FALSE(turned_model.correct);
  EXPECT_TRUE(turned_faces.correct);
  EXPECT_NEAR(turned_faces.errors.rotation, 0.0, 1e-12);
  EXPECT_NEAR(turned_faces.errors.translation_mm, 0.0, 1e-9);

  const auto upside_model = pb::thesis_judge(upside_down, gt, model, kTable);
  const auto upside_faces = pb::thesis_judge(upside_down, gt, faces, kTable);
  EXPECT_FALSE(upside_model.correct);
  EXPECT_GT(upside_model.errors.rotation, kTable.rotation);
  EXPECT_TRUE(upside_faces.correct);
  EXPECT_NEAR(upside_faces.errors.translation_mm, 0.0, 1e-9);

  const auto off_model = pb::thesis_judge(off, gt, model, kTable);
  const auto off_faces = pb::thesis_judge(off, gt, faces, kTable);
  EXPECT_FALSE(off_model.correct);
  EXPECT_FALSE(off_faces.correct);
  EXPECT_NEAR(off_faces.errors.translation_mm, 60.0, 1e-9);
}

TEST(EvalJudgements, JudgeIsThesisErrorsAndThesisCorrectWithTheSameThresholds) {
  const auto model = carton_model_symmetries();
  pb::Pose gt;
  gt.t = pb::Vec3(0, 0, 900);
  for (double dx : {0.0, 30.0, 49.9, 50.0, 80.0}) {
    pb::Pose est = gt;
    est.R = pb::axis_angle(pb::Vec3(1, 0, 0), 0.3);
    est.t += pb::Vec3(dx, 0, 0);
    const pb::ThesisErrors e = pb::thesis_errors(est, gt, model, {kTable});
    const pb::ThesisJudgement j = pb::thesis_judge(est, gt, model, kTable);
    EXPECT_EQ(j.correct, pb::thesis_correct(e, kTable)) << dx;
    EXPECT_EQ(j.errors.translation_mm, e.translation_mm) << dx;
    EXPECT_EQ(j.errors.rotation, e.rotation) << dx;
    EXPECT_EQ(j.errors.symmetry, e.symmetry) << dx;
  }
}

}  // namespace
