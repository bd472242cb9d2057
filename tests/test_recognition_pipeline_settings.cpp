// parse_recognition_settings / settings_to_json: every YAML section, unknown
// keys rejected with file, line and key, and a JSON that mirrors the parsers
// one to one (every key the parsers accept is serialized, and every
// serialized value parses back to itself).
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <set>
#include <sstream>

#include "recognition/pipeline.h"
#include "recognition/registry.h"

namespace {

pb::RecognitionSettings parse(const std::string& yaml, pb::RecognitionSettings base = {}) {
  return pb::parse_recognition_settings(pb::YamlNode::load_string(yaml, "cfg.yaml"), base);
}

TEST(Settings, DefaultsAreTheThesisValues) {
  const pb::RecognitionSettings s;
  EXPECT_EQ(s.descriptor, "fpfh");
  EXPECT_EQ(s.refinement, "icp");
  EXPECT_EQ(s.views.views, 12);
  EXPECT_EQ(s.preprocess.voxel_mm, 10.0);
  EXPECT_EQ(s.global.top_k, 5);
  EXPECT_EQ(s.local.hough_min_votes, 5);
  EXPECT_EQ(s.refine.max_iterations, 40);
  EXPECT_EQ(s.verify.min_inlier_fraction, 0.0);
}

TEST(Settings, ReadsEverySection) {
  const auto s = parse(R"(
descriptor: cesf
refinement: icp_plane
seed: 99
views: {views: 8, resolution: 128}
preprocess: {voxel_mm: 20, remove_plane: false, max_range_mm: 5000}
local: {hough_bin_mm: 80}
global: {top_k: 7, skip_crh: true}
ppf: {model_points: 200}
refine: {max_iterations: 30}
verify: {inlier_threshold_mm: 15, min_inlier_fraction: 0.25}
)");
  EXPECT_EQ(s.descriptor, "cesf");
  EXPECT_EQ(s.refinement, "icp_plane");
  EXPECT_EQ(s.seed, 99u);
  EXPECT_EQ(s.views.views, 8);
  EXPECT_EQ(s.views.resolution, 128);
  EXPECT_EQ(s.preprocess.voxel_mm, 20.0);
  EXPECT_FALSE(s.preprocess.remove_plane);
  EXPECT_EQ(s.preprocess.max_range_mm, 5000.0);
  EXPECT_EQ(s.local.hough_bin_mm, 80.0);
  EXPECT_EQ(s.global.top_k, 7);
  EXPECT_TRUE(s.global.skip_crh);
  EXPECT_EQ(s.ppf.model_points, 200);
  EXPECT_EQ(s.refine.max_iterations, 30);
  EXPECT_EQ(s.verify.inlier_threshold_mm, 15.0);
  EXPECT_EQ(s.verify.min_inlier_fraction, 0.25);
  // Fields not mentioned keep the base's values.
  pb::RecognitionSettings base;
  base.preprocess.normal_radius_mm = 33;
  EXPECT_EQ(parse("seed: 3", base).preprocess.normal_radius_mm, 33.0);
}

void expect_input_error(const std::string& yaml, const std::string& field, const std::string& in_message) {
  try {
    parse(yaml);
    FAIL() << "no error for:\n" << yaml;
  } catch (const pb::InputError& e) {
    EXPECT_EQ(e.file(), "cfg.yaml");
    EXPECT_EQ(e.field(), field) << e.what();
    EXPECT_NE(std::string(e.what()).find(in_message), std::string::npos) << e.what();
  }
}

TEST(Settings, BadInputNamesFileLineAndKey) {
  expect_input_error("descriptor: cesf\nbogus: 1\n", "bogus", "line 2");
  expect_input_error("preprocess:\n  voxel_mm: 5\n  voxl_mm: 5\n", "preprocess.voxl_mm", "line 3");
  expect_input_error("verify:\n  inlier_treshold_mm: 5\n", "verify.inlier_treshold_mm", "line 2");
  expect_input_error("views:\n  view: 5\n", "views.view", "line 2");
  expect_input_error("descriptor: sift\n", "descriptor", "unknown name 'sift'");
  expect_input_error("refinement: icp2\n", "refinement", "unknown name 'icp2'");
  expect_input_error("preprocess: {voxel_mm: abc}\n", "preprocess.voxel_mm", "malformed");
  expect_input_error("preprocess: {normal_radius_mm: -3}\n", "preprocess.normal_radius_mm", "positive");
  expect_input_error("preprocess: {min_range_mm: 500, max_range_mm: 400}\n", "preprocess.max_range_mm", "greater");
  expect_input_error("verify: {min_inlier_fraction: 1.5}\n", "verify.min_inlier_fraction", "[0, 1]");
  expect_input_error("views: {views: 0}\n", "views.views", "at least 1");
  expect_input_error("seed: -4\n", "seed", "non-negative");
}

// The keys a section's parser accepts, read from its unknown-key message
// ("... (allowed: a, b, c)").
std::set<std::string> allowed_keys(const std::string& section) {
  try {
    parse(section + ":\n  zz_not_a_key: 1\n");
  } catch (const pb::InputError& e) {
    const std::string w = e.what();
    const size_t a = w.find("allowed: ");
    if (a == std::string::npos) return {};
    const size_t b = w.find(')', a);
    std::set<std::string> keys;
    std::stringstream ss(w.substr(a + 9, b - a - 9));
    std::string k;
    while (std::getline(ss, k, ',')) {
      while (!k.empty() && k.front() == ' ') k.erase(k.begin());
      keys.insert(k);
    }
    return keys;
  }
  return {};
}

TEST(Settings, JsonHasEveryFieldEveryParserAccepts) {
  const auto j = nlohmann::json::parse(pb::settings_to_json(pb::RecognitionSettings{}));
  for (const char* top : {"descriptor", "refinement", "views", "preprocess", "local", "global", "ppf", "refine",
                          "verify", "seed"})
    EXPECT_TRUE(j.contains(top)) << top;
  for (const char* sec : {"views", "preprocess", "local", "global", "ppf", "refine", "verify"}) {
    std::set<std::string> in_json;
    for (auto it = j[sec].begin(); it != j[sec].end(); ++it) in_json.insert(it.key());
    EXPECT_EQ(in_json, allowed_keys(sec)) << "section " << sec
                                          << ": settings_to_json and the section's parser disagree";
  }
}

// Every value of the JSON is perturbed (ints + 1, doubles * 0.9, booleans
// flipped), fed back as YAML (JSON is YAML) and must come back unchanged:
// each serialized key lands in the field it was serialized from.
TEST(Settings, JsonRoundTripsThroughTheParsers) {
  nlohmann::json j = nlohmann::json::parse(pb::settings_to_json(pb::RecognitionSettings{}));
  for (auto& [sec, v] : j.items()) {
    if (!v.is_object()) continue;
    for (auto& [k, x] : v.items()) {
      if (x.is_boolean()) x = !x.get<bool>();
      else if (x.is_number_integer()) x = x.get<long long>() + 1;
      else if (x.is_number_float()) x = x.get<double>() * 0.9;
    }
  }
  j["seed"] = 12345;
  j["descriptor"] = "ourcvfh";
  j["refinement"] = "ndt";
  const auto s = parse(j.dump());
  EXPECT_EQ(nlohmann::json::parse(pb::settings_to_json(s)), j);
  EXPECT_NE(pb::settings_to_json(s), pb::settings_to_json(pb::RecognitionSettings{}));
}

TEST(Settings, NamesAreTheIssuesList) {
  EXPECT_EQ(pb::descriptor_names(),
            (std::vector<std::string>{"fpfh", "shot", "cvfh", "esf", "cesf", "ourcvfh", "ppf"}));
  EXPECT_EQ(pb::refinement_names(), (std::vector<std::string>{"none", "icp", "icp_lm", "icp_plane", "icp_pcl", "icp_plane_pcl", "gicp", "ndt"}));
}

}  // namespace
