// The experiment section `judgements:` (INTERFACES.md section 3): Table 4.5
// declares the thesis's "faces on faces" set for the milk carton, parsed
// with the models.yaml symmetry reader; a malformed or misspelt entry is an
// InputError naming the file, the line and the key. How a pose is judged
// over such a set: tests/test_eval_judgements.cpp.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/error.h"
#include "eval/symmetry.h"
#include "runner/experiment.h"

namespace {

TEST(Judgements, Table45DeclaresFacesWithTheEightRotationsOfTheBody) {
  const std::string src = POSEBENCH_SOURCE_DIR;
  std::filesystem::current_path(src);  // the config's paths are relative to the project root
  const pb::ExperimentConfig cfg = pb::load_experiment("configs/thesis/table_4_5.yaml");
  ASSERT_EQ(cfg.judgements.size(), 1u);
  const pb::Judgement& faces = cfg.judgements[0];
  EXPECT_EQ(faces.name, "faces");
  EXPECT_FALSE(faces.description.empty());
  EXPECT_EQ(faces.symmetries_discrete.size(), 7u);  // the identity is implicit
  EXPECT_TRUE(faces.symmetries_continuous.empty());
  EXPECT_EQ(pb::symmetry_transformations(faces.symmetries_discrete, faces.symmetries_continuous).size(), 8u);
  // The set is part of the experiment's identity (its hash guards results).
  ASSERT_TRUE(cfg.canonical.contains("judgements"));
  EXPECT_EQ(cfg.canonical["judgements"][0]["name"], "faces");
  EXPECT_EQ(cfg.canonical["judgements"][0]["symmetries_discrete"].size(), 7u);
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

TEST(Judgements, MisspeltKeyIsAnInputErrorNamingFileLineAndKey) {
  const std::string dir = ::testing::TempDir();
  const std::string path = dir + "/j2.yaml";
  {
    std::ofstream out(path);
    out << "object: x\nscenes: [{dataset: " << dir << "}]\ndescriptors: [fpfh]\n"
        << "judgements:\n  faces:\n    symmetries_discret: []\n";
  }
  try {
    pb::load_experiment(path);
    FAIL() << "no error";
  } catch (const pb::InputError& e) {
    EXPECT_EQ(e.file(), path);
    EXPECT_NE(std::string(e.what()).find("symmetries_discret"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("line 6"), std::string::npos) << e.what();
  }
}

}  // namespace
