// The milk carton's two judgements (Table 4.5): the symmetries of
// models/models.yaml (the half turn about its vertical axis) and the thesis's
// "faces on faces" set declared in configs/thesis/table_4_5.yaml. A carton
// turned 90 degrees about its axis, or upside down, is wrong under the
// first and correct under the second; a pose 60 mm off is wrong under both.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "core/error.h"
#include "core/rotation.h"
#include "eval/errors.h"
#include "eval/symmetry.h"
#include "models/registry.h"
#include "runner/experiment.h"

namespace {

bool correct(const pb::Pose& est, const pb::Pose& gt, const std::vector<pb::Pose>& syms) {
  const pb::ThesisThresholds thr{50.0, 0.05};
  return pb::thesis_correct(pb::thesis_errors(est, gt, syms, {thr}), thr);
}

TEST(Judgements, CartonFacesOnFacesVersusTheModelsSymmetries) {
  const std::string src = POSEBENCH_SOURCE_DIR;
  std::filesystem::current_path(src);  // the config's paths are relative to the project root
  const pb::ExperimentConfig cfg = pb::load_experiment("configs/thesis/table_4_5.yaml");
  ASSERT_EQ(cfg.judgements.size(), 1u);
  const pb::Judgement& faces = cfg.judgements[0];
  EXPECT_EQ(faces.name, "faces");
  const auto face_syms = pb::symmetry_transformations(faces.symmetries_discrete, faces.symmetries_continuous);
  EXPECT_EQ(face_syms.size(), 8u);
  const pb::ModelRegistry reg = pb::ModelRegistry::load(src + "/models/models.yaml");
  const pb::ModelSpec& carton = reg.spec("milk_carton");
  const auto model_syms = pb::symmetry_transformations(carton.symmetries_discrete, carton.symmetries_continuous);
  ASSERT_EQ(model_syms.size(), 2u);  // identity and the half turn

  pb::Pose gt;
  gt.R = pb::axis_angle(pb::Vec3(0.3, -1, 0.2), 0.7);
  gt.t = pb::Vec3(40, -20, 800);
  auto composed = [&](const pb::Mat3& R, const pb::Vec3& t_model) {  // gt * (x -> R x + t)
    pb::Pose S;
    S.R = R;
    S.t = t_model;
    return gt * S;
  };
  const pb::Vec3 c(0, 0, -22.5);  // body centre, model frame
  const pb::Mat3 Rz90 = pb::axis_angle(pb::Vec3::UnitZ(), M_PI / 2);
  const pb::Mat3 flip = pb::Vec3(1, -1, -1).asDiagonal();
  const pb::Pose turned = composed(Rz90, c - Rz90 * c);
  const pb::Pose upside_down = composed(flip, c - flip * c);
  pb::Pose off = gt;
  off.t += pb::Vec3(60, 0, 0);

  EXPECT_TRUE(correct(gt, gt, model_syms));
  EXPECT_TRUE(correct(gt, gt, face_syms));
  EXPECT_FALSE(correct(turned, gt, model_syms));
  EXPECT_TRUE(correct(turned, gt, face_syms));
  EXPECT_FALSE(correct(upside_down, gt, model_syms));
  EXPECT_TRUE(correct(upside_down, gt, face_syms));
  EXPECT_FALSE(correct(off, gt, model_syms));
  EXPECT_FALSE(correct(off, gt, face_syms));
}

TEST(Judgements, BadSymmetryIsAnInputErrorNamingTheField) {
  const std::string dir = ::testing::TempDir();
  const std::string path = dir + "/j.yaml";
  {
    std::ofstream out(path);
    out << "object: x\nscenes: [{dataset: " << dir << "}]\ndescriptors: [fpfh]\n"
        << "judgements:\n  faces:\n    symmetries_discrete:\n      - [[2, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], "
           "[0, 0, 0, 1]]\n";
  }
  try {
    pb::load_experiment(path);
    FAIL() << "no error";
  } catch (const pb::InputError& e) {
    EXPECT_EQ(e.file(), path);
    EXPECT_NE(std::string(e.what()).find("judgements.faces.symmetries_discrete"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("not a rotation"), std::string::npos) << e.what();
  }
}

}  // namespace
