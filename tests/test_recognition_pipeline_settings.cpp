// parse_recognition_settings / settings_to_json: every YAML section, unknown
// keys rejected with file, line and key, and a JSON that mirrors the parsers
// one to one (every key the parsers accept is serialized, and every
// serialized value parses back to itself).
#include <gtest/gtest.h>

#include "core/random.h"
#include <nlohmann/json.hpp>

#include <set>
#include <sstream>

#include "core/random.h"
#include "recognition/pipeline.h"
#include "recognition/registry.h"

namespace {

pb::RecognitionSettings parse(const std::string& yaml, pb::RecognitionSettings base = {}) {
  return pb::parse_recognition_settings(pb::YamlNode::load_string(yaml, "cfg.yaml"), base);
}

// The thesis's values, except where measurement moved a default (the thesis
// configs pin the thesis's: global.top_k 5, local.matches_per_keypoint 1,
// results/real_recognition).
TEST(Settings, DefaultsAreTheDocumentedValues) {
  const pb::RecognitionSettings s;
  EXPECT_EQ(s.descriptor, "fpfh");
  EXPECT_EQ(s.refinement, "icp");
  EXPECT_EQ(s.views.views, 12);
  EXPECT_EQ(s.preprocess.voxel_mm, 10.0);
  EXPECT_EQ(s.global.top_k, 20);
  EXPECT_EQ(s.local.hough_min_votes, 5);
  EXPECT_EQ(s.local.matches_per_keypoint, 3);
  EXPECT_EQ(s.local.max_hypotheses, 40);
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
                          "verify", "scale", "seed"})
    EXPECT_TRUE(j.contains(top)) << top;
  for (const char* sec : {"views", "preprocess", "local", "global", "ppf", "refine", "verify", "scale"}) {
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

// A grid point's override goes through the section parsers: rules, relative
// lengths and unknown keys as in a YAML section, the error at the value's
// own line.
TEST(Settings, ApplySettingReadsOneFieldByItsPath) {
  const pb::YamlNode grid = pb::YamlNode::load_string("a: 7\nb: 0.04d\nc: -1\nd: shot\ne: 3\n", "exp.yaml");
  pb::RecognitionSettings s = pb::apply_setting({}, "global.top_k", grid["a"]);
  EXPECT_EQ(s.global.top_k, 7);
  s = pb::apply_setting(s, "preprocess.voxel_mm", grid["b"]);
  EXPECT_DOUBLE_EQ(s.relative.at("preprocess.voxel_mm"), 0.04);
  s = pb::apply_setting(s, "preprocess.voxel_mm", grid["e"]);
  EXPECT_EQ(s.relative.count("preprocess.voxel_mm"), 0u);
  EXPECT_EQ(s.preprocess.voxel_mm, 3);
  EXPECT_EQ(pb::apply_setting(s, "descriptor", grid["d"]).descriptor, "shot");
  s = pb::apply_setting(s, "refine.ndt.resolution_mm", grid["b"]);  // a nested subsection
  EXPECT_DOUBLE_EQ(s.relative.at("refine.ndt.resolution_mm"), 0.04);
  EXPECT_EQ(pb::apply_setting(s, "refine.icp.coarse_points", grid["e"]).refine.icp.coarse_points, 3);
  try {
    pb::apply_setting(s, "global.top_k", grid["c"]);
    FAIL() << "a negative top_k was accepted";
  } catch (const pb::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("exp.yaml"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("top_k"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("line 3"), std::string::npos) << e.what();
  }
  EXPECT_THROW(pb::apply_setting(s, "global.no_such_key", grid["a"]), pb::InputError);
  EXPECT_THROW(pb::apply_setting(s, "nosection.top_k", grid["a"]), pb::InputError);
}

// A trial's settings cross the process boundary as their changes from the
// defaults; read back over the defaults they are the same settings.
TEST(Settings, ChangesFromTheDefaultsReadBackToTheSameSettings) {
  const pb::RecognitionSettings none;
  EXPECT_EQ(pb::settings_changes_json(none).dump(), R"({"descriptor":"fpfh","refinement":"icp"})");
  const pb::RecognitionSettings s =
      parse("descriptor: ppf\npreprocess: {voxel_mm: 7, normal_radius_mm: 0.2d}\nglobal: {top_k: 3}\n"
            "verify: {max_instances: 2}\nseed: 9\n");
  const nlohmann::ordered_json c = pb::settings_changes_json(s);
  EXPECT_EQ(c["preprocess"].dump(), R"({"voxel_mm":7.0,"normal_radius_mm":"0.2d"})");
  EXPECT_FALSE(c.contains("local"));
  EXPECT_EQ(pb::settings_to_json(parse(c.dump())), pb::settings_to_json(s));
}

// Lengths relative to the object's diameter (issue 9): "0.05d" in YAML, the
// default profile, resolution with the sensor's floor.
TEST(RelativeLengths, TheDefaultProfileGivesTheHeaderValuesAt200mm) {
  const pb::RecognitionSettings d;
  EXPECT_EQ(d.relative.at("preprocess.voxel_mm"), 0.05);
  const pb::RecognitionSettings r = pb::resolve_lengths(d, 200);
  EXPECT_TRUE(r.relative.empty());
  pb::RecognitionSettings header = d;
  header.relative.clear();
  EXPECT_EQ(pb::settings_to_json(r), pb::settings_to_json(header));
  // ... and scales with the object: 30x smaller, 30x shorter.
  const pb::RecognitionSettings small = pb::resolve_lengths(d, 50);
  EXPECT_DOUBLE_EQ(small.preprocess.voxel_mm, 2.5);
  EXPECT_DOUBLE_EQ(small.local.descriptor_radius_mm, 15);
  EXPECT_DOUBLE_EQ(small.verify.inlier_threshold_mm, 2.5);
  const pb::RecognitionSettings large = pb::resolve_lengths(d, 1500);
  EXPECT_DOUBLE_EQ(large.local.hough_bin_mm, 375);
  EXPECT_DOUBLE_EQ(large.refine.max_correspondence_mm, 150);
  // Counts, angles and ranges are not lengths of the object.
  EXPECT_EQ(large.ppf.model_points, d.ppf.model_points);
  EXPECT_EQ(large.preprocess.max_range_mm, d.preprocess.max_range_mm);
}

TEST(RelativeLengths, YamlGivesEitherMmOrAFractionOfTheDiameter) {
  const auto s = parse("preprocess: {voxel_mm: 12}\nlocal: {hough_bin_mm: 0.4d}\nscale: {diameter_mm: 300}\n");
  EXPECT_EQ(s.relative.count("preprocess.voxel_mm"), 0u);
  EXPECT_EQ(s.relative.at("local.hough_bin_mm"), 0.4);
  const auto r = pb::resolve_lengths(s, 99);  // scale.diameter_mm wins over the model's
  EXPECT_EQ(r.preprocess.voxel_mm, 12);
  EXPECT_DOUBLE_EQ(r.local.hough_bin_mm, 120);
  EXPECT_DOUBLE_EQ(r.local.descriptor_radius_mm, 90);  // default 0.3d
  // The JSON writes relative fields back as they were given, and parses back.
  const auto j = nlohmann::json::parse(pb::settings_to_json(s));
  EXPECT_EQ(j["local"]["hough_bin_mm"], "0.4d");
  EXPECT_EQ(j["preprocess"]["voxel_mm"], 12);
  EXPECT_EQ(pb::settings_to_json(parse(j.dump())), pb::settings_to_json(s));
  // A base's mm value under a later "0.05d" becomes relative again.
  const auto again = parse("preprocess: {voxel_mm: 0.05d}\n", s);
  EXPECT_DOUBLE_EQ(pb::resolve_lengths(again, 0).preprocess.voxel_mm, 15);
}

TEST(RelativeLengths, TheSensorsFloorAndTheCasesThatCannotResolve) {
  pb::RecognitionSettings s;
  s.scale.min_length_mm = 4;
  const auto r = pb::resolve_lengths(s, 50);  // a 5 cm part: voxel 2.5 mm -> the 4 mm floor
  EXPECT_EQ(r.preprocess.voxel_mm, 4);
  EXPECT_DOUBLE_EQ(r.local.descriptor_radius_mm, 15);  // above the floor
  // The floor from an image: 2 px at the median depth 1000 mm with fx 500.
  pb::Intrinsics K;
  K.fx = K.fy = 500;
  K.width = 4;
  K.height = 1;
  pb::DepthImage im;
  im.width = 4;
  im.height = 1;
  im.z = {900, 1000, 0, 1100};
  EXPECT_DOUBLE_EQ(pb::sensor_length_floor_mm(s.scale, im, K), 4.0);
  const auto f = pb::resolve_for_scene(pb::RecognitionSettings{}, 50, im, K);
  EXPECT_DOUBLE_EQ(f.scale.min_length_mm, 4.0);
  EXPECT_DOUBLE_EQ(f.preprocess.voxel_mm, 4.0);
  // No diameter: an input error naming scale.diameter_mm.
  try {
    pb::resolve_lengths(pb::RecognitionSettings{}, 0);
    ADD_FAILURE() << "resolved without a diameter";
  } catch (const pb::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("scale.diameter_mm"), std::string::npos) << e.what();
  }
  // A number set in code on a field that is still relative is not ignored.
  pb::RecognitionSettings code;
  code.preprocess.voxel_mm = 8;
  EXPECT_THROW(pb::resolve_lengths(code, 200), std::logic_error);
  code.relative.erase("preprocess.voxel_mm");
  EXPECT_EQ(pb::resolve_lengths(code, 200).preprocess.voxel_mm, 8);
}

// The depth noise estimate: a tilted plane (perspective, no noise) gives
// almost none; the same plane with Gaussian noise of 2 mm gives 2 mm within
// 5%; the floor is then the larger of 2 px and 2 sigma.
TEST(RelativeLengths, TheSensorsNoiseRaisesTheFloor) {
  pb::Intrinsics K;
  K.fx = K.fy = 500;
  K.cx = 160;
  K.cy = 120;
  K.width = 320;
  K.height = 240;
  pb::DepthImage plane(320, 240);
  for (int v = 0; v < 240; ++v)
    for (int u = 0; u < 320; ++u) {  // the plane z = 1000 + 0.8 x (45 degrees-ish), along the ray
      const double rx = (u - K.cx) / K.fx;
      plane.z[static_cast<size_t>(v * 320 + u)] = static_cast<float>(1000.0 / (1.0 - 0.8 * rx));
    }
  EXPECT_LT(pb::depth_noise_sigma_mm(plane), 0.05);
  pb::DepthImage noisy = plane;
  pb::Rng rng(5);
  for (float& z : noisy.z) z += static_cast<float>(rng.normal(0.0, 2.0));
  EXPECT_NEAR(pb::depth_noise_sigma_mm(noisy), 2.0, 0.1);
  pb::ScaleSettings scale;  // 2 px at the median depth (about 1000 mm): 4 mm; 2 sigma: 4 mm
  scale.sensor_floor_sigmas = 3;
  EXPECT_NEAR(pb::sensor_length_floor_mm(scale, noisy, K), 6.0, 0.3);
  scale.sensor_floor_sigmas = 0;
  EXPECT_NEAR(pb::sensor_length_floor_mm(scale, noisy, K), 4.0, 0.2);
  scale.sensor_floor_px = 0;
  scale.sensor_floor_sigmas = 2;
  EXPECT_NEAR(pb::sensor_length_floor_mm(scale, noisy, K), 4.0, 0.2);
  // A malformed image (fewer values than its size) gives no estimate, no read past its end.
  pb::DepthImage short_image;
  short_image.width = 10;
  short_image.height = 10;
  short_image.z.assign(5, 1000.f);
  EXPECT_EQ(pb::depth_noise_sigma_mm(short_image), 0.0);
}

TEST(RelativeLengths, BadFractionsNameTheKey) {
  expect_input_error("preprocess: {voxel_mm: -0.05d}\n", "preprocess.voxel_mm", "positive fraction");
  expect_input_error("preprocess: {voxel_mm: 0d}\n", "preprocess.voxel_mm", "positive fraction");
  expect_input_error("local: {hough_bin_mm: 0.1dd}\n", "local.hough_bin_mm", "malformed");
  // Not a length: a fraction is malformed there.
  expect_input_error("local: {hough_min_votes: 0.1d}\n", "local.hough_min_votes", "malformed");
}

TEST(Settings, NamesAreTheIssuesList) {
  EXPECT_EQ(pb::descriptor_names(),
            (std::vector<std::string>{"fpfh", "shot", "cvfh", "esf", "cesf", "ourcvfh", "ppf"}));
  EXPECT_EQ(pb::refinement_names(), (std::vector<std::string>{"none", "icp", "icp_lm", "icp_plane", "icp_pcl", "icp_plane_pcl", "gicp", "ndt"}));
}

// The relative inlier threshold is capped at verify.inlier_threshold_max_voxels
// preprocess voxels: the warehouse's 0.05 d (1.8 m LS5, 20 mm voxel) is 4.5
// voxels, enough to count the LS5's 180-degree flip as inliers.
TEST(RelativeLengths, TheInlierThresholdIsAtMostTwoVoxels) {
  const auto warehouse = pb::resolve_lengths(parse("preprocess: {voxel_mm: 20}\n"), 1800);
  EXPECT_DOUBLE_EQ(warehouse.verify.inlier_threshold_mm, 40);  // not 0.05 d = 90
  const auto table = pb::resolve_lengths(parse("preprocess: {voxel_mm: 10}\n"), 180);
  EXPECT_DOUBLE_EQ(table.verify.inlier_threshold_mm, 9);  // 0.05 d: below the cap
  // No cap, a threshold given in mm, or a sensor floor above the cap.
  const auto uncapped =
      pb::resolve_lengths(parse("preprocess: {voxel_mm: 20}\nverify: {inlier_threshold_max_voxels: 0}\n"), 1800);
  EXPECT_DOUBLE_EQ(uncapped.verify.inlier_threshold_mm, 90);
  const auto given = pb::resolve_lengths(parse("preprocess: {voxel_mm: 20}\nverify: {inlier_threshold_mm: 70}\n"), 1800);
  EXPECT_DOUBLE_EQ(given.verify.inlier_threshold_mm, 70);
  const auto floored = pb::resolve_lengths(parse("preprocess: {voxel_mm: 20}\nscale: {min_length_mm: 50}\n"), 1800);
  EXPECT_DOUBLE_EQ(floored.verify.inlier_threshold_mm, 50);
  // The default profile at 200 mm: voxel 10 mm, threshold 10 mm (1 voxel).
  EXPECT_DOUBLE_EQ(pb::resolve_lengths(pb::RecognitionSettings{}, 200).verify.inlier_threshold_mm, 10);
}

}  // namespace
