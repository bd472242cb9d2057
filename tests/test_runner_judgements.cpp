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

// The InputError load_experiment throws for an experiment whose
// `judgements:` section is `section` (YAML, from its line 4 on).
pb::InputError judgements_error(const std::string& name, const std::string& section) {
  const std::string dir = ::testing::TempDir();
  const std::string path = dir + "/" + name + ".yaml";
  std::ofstream(path) << "object: x\nscenes: [{dataset: " << dir << "}]\ndescriptors: [fpfh]\n"
                      << "judgements:\n" << section;
  try {
    pb::load_experiment(path);
  } catch (const pb::InputError& e) {
    EXPECT_EQ(e.file(), path);
    return e;
  }
  ADD_FAILURE() << "no error for " << section;
  return pb::InputError(path, "", "");
}

TEST(Judgements, BadSymmetryIsAnInputErrorNamingTheField) {
  const std::string w = judgements_error("j1", "  faces:\n    symmetries_discrete:\n"
                                               "      - [[2, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]\n")
                            .what();
  EXPECT_NE(w.find("judgements.faces.symmetries_discrete"), std::string::npos) << w;
  EXPECT_NE(w.find("not a rotation"), std::string::npos) << w;
}

TEST(Judgements, MisspeltKeyIsAnInputErrorNamingFileLineAndKey) {
  const std::string w = judgements_error("j2", "  faces:\n    symmetries_discret: []\n").what();
  EXPECT_NE(w.find("symmetries_discret"), std::string::npos) << w;
  EXPECT_NE(w.find("line 6"), std::string::npos) << w;
}

}  // namespace
