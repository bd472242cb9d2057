// Experiment YAML text, two findings of fuzz/fuzz_experiment_yaml.cpp, both
// internal errors without a check: bytes that are not UTF-8 (yaml-cpp passes
// them on and the JSON dump of the config throws) are an InputError naming the file
// and the line, in every YAML loader (core/yaml.cpp), while UTF-8 text is
// accepted; and a document that yaml-cpp reads into an invalid node (a '%'
// directive line after content) is an InputError naming the file, not
// YAML::InvalidNode.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "core/error.h"
#include "core/yaml.h"
#include "runner/experiment.h"

namespace {

std::string write(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + "/" + name;
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

std::string experiment(const std::string& scene_name) {
  return "object: ls5\nscenes:\n  - name: " + scene_name + "\n    dataset: " + ::testing::TempDir() +
         "\ndescriptors: [fpfh]\n";
}

TEST(ExperimentYaml, BytesThatAreNotUtf8AreAnInputErrorNamingFileAndLine) {
  for (const std::string bad : {std::string("t\xff"), std::string("t\xc3"), std::string("t\xc0\xaf"),
                                std::string("t\xed\xa0\x80"), std::string("t\xf4\x90\x80\x80")}) {
    const std::string path = write("not_utf8.yaml", experiment(bad));
    try {
      pb::load_experiment(path);
      ADD_FAILURE() << "no error";
    } catch (const pb::InputError& e) {
      EXPECT_EQ(e.file(), path);
      EXPECT_NE(std::string(e.what()).find("not UTF-8 text: line 3"), std::string::npos) << e.what();
    }
  }
}

// A key given twice is an InputError naming the file, the key's path and
// both lines, wherever it is: a checked section, the free-form generator
// overrides (converted to JSON, where the copies collapsed silently), or
// the top level.
TEST(ExperimentYaml, AKeyGivenTwiceIsAnInputErrorNamingFileKeyAndLines) {
  const std::string scene = "object: ls5\nscenes:\n  - name: a\n    generate: " + std::string(POSEBENCH_SOURCE_DIR) +
                            "/configs/scenes/table_astra.yaml\n";
  const std::pair<std::string, std::string> cases[] = {
      {scene + "    generator: {images: 2, noise: {model: none}, images: 3}\ndescriptors: [fpfh]\n",
       "scenes[0].generator.images"},
      {scene + "    settings:\n      preprocess: {voxel_mm: 5}\n      preprocess: {voxel_mm: 6}\ndescriptors: [fpfh]\n",
       "scenes[0].settings.preprocess"},
      {scene + "descriptors: [fpfh]\ndescriptors: [shot]\n", "descriptors"}};
  for (const auto& [text, field] : cases) {
    const std::string path = write("twice.yaml", text);
    try {
      pb::load_experiment(path);
      ADD_FAILURE() << "no error for " << field;
    } catch (const pb::InputError& e) {
      EXPECT_EQ(e.file(), path);
      EXPECT_EQ(e.field(), field) << e.what();
      EXPECT_NE(std::string(e.what()).find("key given twice, at lines"), std::string::npos) << e.what();
    }
  }
}

TEST(ExperimentYaml, Utf8TextIsAccepted) {
  const std::string path = write("utf8.yaml", experiment("caf\xc3\xa9_\xe2\x82\xac_\xf0\x9f\x93\xa6"));
  const pb::YamlNode root = pb::YamlNode::load_file(path);
  EXPECT_EQ(root["scenes"].at(0)["name"].as<std::string>(), "caf\xc3\xa9_\xe2\x82\xac_\xf0\x9f\x93\xa6");
}

TEST(ExperimentYaml, ADirectiveAfterContentIsAnInputError) {
  const std::string path = write("directive.yaml", "object: ls5\nregistration_only: true\n%perturb_deg: 15\n");
  try {
    pb::load_experiment(path);
    ADD_FAILURE() << "no error";
  } catch (const pb::InputError& e) {
    EXPECT_EQ(e.file(), path);
  }
}

}  // namespace

// A path component longer than the OS allows (NAME_MAX) in `generate:`: the
// filesystem check can throw std::filesystem::filesystem_error (found by
// fuzz_experiment_yaml); the loader reports the scene config "not found".
TEST(ExperimentYaml, APathTooLongForTheOsIsAnInputError) {
  const std::string long_name(300, 'x');
  const std::string path = write("too_long.yaml", "object: ls5\nscenes:\n  - generate: configs/" + long_name +
                                                      ".yaml\ndescriptors: [fpfh]\n");
  try {
    pb::load_experiment(path);
    ADD_FAILURE() << "no error";
  } catch (const pb::InputError& e) {
    EXPECT_EQ(e.file(), path);
    EXPECT_NE(std::string(e.what()).find("scene config not found"), std::string::npos) << e.what();
  }
}

// Control characters YAML does not allow in a stream: yaml-cpp turned a NUL
// byte in a name into bytes that are not UTF-8, and the experiment's JSON
// dump threw (found by fuzz_experiment_yaml). Tabs, CR and NEL stay allowed.
TEST(ExperimentYaml, ControlCharactersAreAnInputErrorNamingLineAndByte) {
  for (const std::string bad : {std::string("a\0b", 3), std::string("a\x08"), std::string("a\x7f"),
                                std::string("a\xc2\x80"), std::string("a\xef\xbf\xbf")}) {
    const std::string path = write("control.yaml", experiment(bad));
    try {
      pb::load_experiment(path);
      ADD_FAILURE() << "no error";
    } catch (const pb::InputError& e) {
      EXPECT_EQ(e.file(), path);
      EXPECT_NE(std::string(e.what()).find("control character"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("line 3"), std::string::npos) << e.what();
    }
  }
  const std::string ok = write("tab.yaml", "# a\tcomment\r\n" + experiment("n\xc2\x85x"));
  EXPECT_NO_THROW(pb::YamlNode::load_file(ok));
}
