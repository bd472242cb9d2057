// posebench generate on bad input: exit code 2, one message naming the file
// and the field, and no output folder left looking complete.
#include <gtest/gtest.h>

#include <filesystem>

#include "cli_test_util.h"

namespace fs = std::filesystem;

namespace {

// Runs generate on `yaml` (written to cfg.yaml, or `name`) and checks the
// failure contract; returns stderr.
std::string expect_input_error(const std::string& yaml, const std::vector<std::string>& must_contain,
                               const std::string& name = "cfg.yaml", const std::string& extra_setup = "") {
  pbcli::TempDir tmp;
  pbcli::write_file(tmp.path + "/" + name, yaml);
  if (!extra_setup.empty()) pbcli::write_file(tmp.path + "/registry.yaml", extra_setup);
  const auto r = pbcli::run("generate " + name + " --out out --quiet", tmp.path);
  EXPECT_EQ(r.code, 2) << r.err;
  // One message, one line.
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("error"), std::string::npos) << r.err;
  for (const auto& s : must_contain) EXPECT_NE(r.err.find(s), std::string::npos) << "'" << s << "' not in: " << r.err;
  EXPECT_FALSE(fs::exists(tmp.path + "/out")) << r.err;
  EXPECT_FALSE(fs::exists(tmp.path + "/out.partial")) << r.err;
  return r.err;
}

}  // namespace

TEST(CliGenerateErrors, MalformedYaml) {
  expect_input_error("scenario: table\ncamera: {distance_mm: [600, 1500\n", {"broken.yaml", "line"}, "broken.yaml");
}

TEST(CliGenerateErrors, UnknownSensor) {
  expect_input_error("scenario: table\nsensor: lidar9000\n", {"cfg.yaml", "sensor", "lidar9000"});
}

TEST(CliGenerateErrors, UnknownScenario) {
  expect_input_error("scenario: kitchen\n", {"cfg.yaml", "scenario", "kitchen"});
}

TEST(CliGenerateErrors, UnknownKey) {
  expect_input_error("scenario: table\nimgaes: 3\n", {"cfg.yaml", "imgaes", "line 2"});
}

TEST(CliGenerateErrors, NegativeSizes) {
  expect_input_error("scenario: table\ncamera: {distance_mm: [-600, 1500]}\n", {"cfg.yaml", "camera.distance_mm"});
  expect_input_error("scenario: table\ntable: {size_mm: -100}\n", {"cfg.yaml", "table.size_mm"});
  expect_input_error("scenario: table\nimages: -2\n", {"cfg.yaml", "images"});
  expect_input_error("scenario: warehouse\nwarehouse: {object_size_mm: [-1000, 1500]}\n",
                     {"cfg.yaml", "warehouse.object_size_mm"});
}

TEST(CliGenerateErrors, UnknownModel) {
  expect_input_error("scenario: table\ntarget: unicorn\n", {"cfg.yaml", "target", "unicorn"});
}

TEST(CliGenerateErrors, MissingMesh) {
  // A registry whose entry points to a mesh file that does not exist.
  const std::string registry =
      "models:\n"
      "  ghost:\n"
      "    obj_id: 1\n"
      "    source: meshes/ghost.obj\n"
      "  cube:\n"
      "    obj_id: 2\n"
      "    source: generated:box:50x50x50\n";
  expect_input_error("scenario: table\nregistry: registry.yaml\ntarget: ghost\ndistractors: {pool: [cube]}\n",
                     {"cfg.yaml", "target", "ghost.obj"}, "cfg.yaml", registry);
}

TEST(CliGenerateErrors, UnreadableMesh) {
  // The mesh file exists but is not a mesh.
  pbcli::TempDir tmp;
  pbcli::write_file(tmp.path + "/meshes/junk.obj", "this is not a mesh\n\x01\x02\x03");
  pbcli::write_file(tmp.path + "/registry.yaml",
                    "models:\n  junk:\n    obj_id: 1\n    source: meshes/junk.obj\n"
                    "  cube:\n    obj_id: 2\n    source: generated:box\n");
  pbcli::write_file(tmp.path + "/cfg.yaml",
                    "scenario: table\nregistry: registry.yaml\ntarget: junk\ndistractors: {pool: [cube]}\n");
  const auto r = pbcli::run("generate cfg.yaml --out out --quiet", tmp.path);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("junk"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(tmp.path + "/out"));
  EXPECT_FALSE(fs::exists(tmp.path + "/out.partial"));
}

TEST(CliGenerateErrors, MissingConfigAndBadOptions) {
  pbcli::TempDir tmp;
  auto r = pbcli::run("generate nothere.yaml --out out", tmp.path);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("nothere.yaml"), std::string::npos) << r.err;
  pbcli::write_file(tmp.path + "/cfg.yaml", "scenario: table\n");
  r = pbcli::run("generate cfg.yaml --out out --images 0", tmp.path);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--images"), std::string::npos) << r.err;
  // An existing folder that is not a scene set is not overwritten.
  pbcli::write_file(tmp.path + "/mine/notes.txt", "precious");
  r = pbcli::run("generate cfg.yaml --out mine --images 1 --quiet", tmp.path);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--out"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::exists(tmp.path + "/mine/notes.txt"));
  EXPECT_FALSE(fs::exists(tmp.path + "/mine.partial"));
}

TEST(CliGenerateErrors, MissingRegistry) {
  expect_input_error("scenario: table\nregistry: nowhere/models.yaml\n", {"cfg.yaml", "registry", "nowhere/models.yaml"});
}
