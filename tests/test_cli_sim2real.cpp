// posebench sensor-fit and twin on a scene set whose sensor is known: the
// fit finds the noise that made the frames (a closed loop: the generated
// set stands in for real frames with ground truth), the twin keeps the
// frames' ground truth, intrinsics and, with --keep-background, their depth
// outside the objects; an experiment pairs a set with its twin; bad input
// is one message and exit code 2.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "cli_test_util.h"
#include "io/bop.h"
#include "io/png.h"

namespace fs = std::filesystem;

namespace {

// The "real" frames: a structured-light sensor far from the default
// profile (less noise, wider smoothing, fewer edge effects).
const char* kTruthNoise =
    "{model: structured_light, disparity_sigma_px: 0.2, smoothing_radius_px: 2, max_incidence_deg: 85, "
    "edge_bleed_px: 0, edge_dropout_rate: 0.1, edge_dropout_px: 2}";

std::string config(int images) {
  return std::string("scenario: table\nseed: 17\nimages: ") + std::to_string(images) +
         "\nsensor: astra\nnoise: " + kTruthNoise +
         "\ntarget: ls5\ntarget_upright_probability: 1.0\nmin_target_visib: 0.85\n"
         "distractors: {pool: [milk_carton, boletus, box_small, cylinder], count: [3, 5]}\n"
         "occlusion: none\ncamera: {distance_mm: [700, 1300], elevation_deg: [30, 60]}\n";
}

// A generated set in tmp/real (once per test binary run and folder).
void make_real(const std::string& dir, int images) {
  pbcli::write_file(dir + "/real.yaml", config(images));
  const auto g = pbcli::run("generate real.yaml --out real --quiet --threads 1", dir);
  ASSERT_EQ(g.code, 0) << g.err;
}

}  // namespace

TEST(CliSim2Real, SensorFitFindsTheNoiseThatMadeTheFrames) {
  pbcli::TempDir tmp;
  make_real(tmp.path, 4);
  const auto r = pbcli::run("sensor-fit real --out fit --base astra --no-plots -q", tmp.path);
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(pbcli::slurp(tmp.path + "/fit/sensor_fit.json"));
  const auto& n = j["profile"]["noise"];
  EXPECT_EQ(n["model"], "structured_light");
  // Each fitted field within one grid step of the truth.
  EXPECT_GE(n["disparity_sigma_px"].get<double>(), 0.1);
  EXPECT_LE(n["disparity_sigma_px"].get<double>(), 0.3);
  EXPECT_LE(std::abs(n["smoothing_radius_px"].get<int>() - 2), 1);
  EXPECT_LE(n["edge_dropout_rate"].get<double>(), 0.2);
  EXPECT_LE(n["edge_bleed_px"].get<double>(), 0.5);
  // The default profile (no edge effects, other noise) is far off; the fit is close.
  const double base = j["loss"]["base"]["total"], fitted = j["loss"]["fitted"]["total"];
  EXPECT_LT(fitted, 0.25 * base) << base << " " << fitted;
  EXPECT_LT(fitted, 0.5);
  // The profile file is a sensor a scene config can name.
  const std::string profile = pbcli::slurp(tmp.path + "/fit/profile.yaml");
  EXPECT_NE(profile.find("edge_dropout_rate"), std::string::npos);
  std::string scene = config(1);
  scene.replace(scene.find("sensor: astra\nnoise: "), std::string("sensor: astra\nnoise: ").size() + std::string(kTruthNoise).size(),
                "sensor: fit/profile.yaml");
  pbcli::write_file(tmp.path + "/again.yaml", scene);
  const auto g = pbcli::run("generate again.yaml --out again --quiet --threads 1", tmp.path);
  ASSERT_EQ(g.code, 0) << g.err;
  EXPECT_NE(g.out.find("sensor fit"), std::string::npos) << g.out;  // the profile's name: the --out folder's
}

TEST(CliSim2Real, TwinKeepsGroundTruthIntrinsicsAndBackground) {
  pbcli::TempDir tmp;
  make_real(tmp.path, 2);
  const auto t = pbcli::run("twin real --sensor astra --out twin --keep-background -q", tmp.path);
  ASSERT_EQ(t.code, 0) << t.err;
  EXPECT_NE(t.out.find("2 images"), std::string::npos) << t.out;
  EXPECT_NE(t.out.find("supporting plane found in 2"), std::string::npos) << t.out;
  const pb::BopDataset real(tmp.path + "/real"), twin(tmp.path + "/twin");
  const pb::SceneInfo a = real.load_scene("test", 1), b = twin.load_scene("test", 1);
  ASSERT_EQ(a.images.size(), b.images.size());
  int outside_differ = 0, inside_differ = 0, inside = 0;
  for (const auto& [iid, im] : a.images) {
    const pb::ImageInfo& tm = b.images.at(iid);
    EXPECT_EQ(tm.K.fx, im.K.fx);
    EXPECT_EQ(tm.K.cy, im.K.cy);
    ASSERT_EQ(tm.gt.size(), im.gt.size());
    for (size_t k = 0; k < im.gt.size(); ++k) {
      EXPECT_EQ(tm.gt[k].obj_id, im.gt[k].obj_id);
      EXPECT_LT((tm.gt[k].T_cam_model.t - im.gt[k].T_cam_model.t).norm(), 1e-6);
    }
    const pb::DepthImage da = real.load_depth("test", 1, im), db = twin.load_depth("test", 1, tm);
    // The union of the objects' visible masks.
    std::vector<uint8_t> mask(da.z.size(), 0);
    for (size_t k = 0; k < im.gt.size(); ++k) {
      int w = 0, h = 0;
      const auto m = pb::read_gray8_png(real.scene_dir("test", 1) + "/mask_visib/" + pb::bop_id(iid) + "_" +
                                            pb::bop_id(static_cast<int>(k)) + ".png",
                                        &w, &h);
      for (size_t p = 0; p < m.size(); ++p) mask[p] |= m[p] != 0;
    }
    for (size_t p = 0; p < da.z.size(); ++p) {
      if (mask[p]) ++inside, inside_differ += da.z[p] != db.z[p];
      else outside_differ += da.z[p] != db.z[p];
    }
  }
  EXPECT_EQ(outside_differ, 0);
  EXPECT_GT(inside_differ, inside / 4);  // another sensor model on the objects
  // The targets are the real set's.
  EXPECT_EQ(pbcli::slurp(tmp.path + "/twin/test_targets_bop19.json").empty(), false);
  EXPECT_EQ(pb::read_test_targets(tmp.path + "/twin/test_targets_bop19.json").size(),
            pb::read_test_targets(tmp.path + "/real/test_targets_bop19.json").size());
}

TEST(CliSim2Real, AnExperimentPairsARealSetWithItsTwin) {
  pbcli::TempDir tmp;
  make_real(tmp.path, 2);
  pbcli::write_file(tmp.path + "/exp.yaml",
                    "name: pair\nseed: 1\nobject: all\n"
                    "scenes:\n"
                    "  - {name: real, dataset: real, targets: test_targets_bop19.json}\n"
                    "  - {name: real_twin, twin_of: real, twin: {sensor: astra}}\n"
                    "descriptors: [ppf]\nrefinements: [icp]\n");
  const auto r = pbcli::run("run exp.yaml --out res --jobs 2 -q", tmp.path);
  ASSERT_EQ(r.code, 0) << r.err;
  const auto rep = pbcli::run("report res --format md,csv", tmp.path);
  ASSERT_EQ(rep.code, 0) << rep.err;
  const size_t targets = pb::read_test_targets(tmp.path + "/real/test_targets_bop19.json").size();
  ASSERT_NE(rep.out.find("## Real and twin"), std::string::npos) << rep.out;
  // One row: ppf+icp, every target paired.
  const std::string row = "| real | real_twin | ppf+icp |  | ";
  const size_t at = rep.out.find(row);
  ASSERT_NE(at, std::string::npos) << rep.out;
  EXPECT_NE(rep.out.find("/" + std::to_string(targets) + " [", at), std::string::npos) << rep.out.substr(at, 200);
  const std::string csv = pbcli::slurp(tmp.path + "/res/twin_gap.csv");
  EXPECT_NE(csv.find("real,real_twin,ppf+icp,," + std::to_string(targets) + ","), std::string::npos) << csv;
}

TEST(CliSim2Real, BadInputIsOneMessageAndExitCode2) {
  pbcli::TempDir tmp;
  fs::create_directories(tmp.path + "/empty");
  auto r = pbcli::run("twin empty --sensor astra --out t", tmp.path);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("empty"), std::string::npos) << r.err;
  r = pbcli::run("twin empty --sensor nosuch --out t", tmp.path);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("unknown sensor 'nosuch'"), std::string::npos) << r.err;
  r = pbcli::run("twin empty --sensor nosuch.yaml --out t", tmp.path);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("sensor profile file 'nosuch.yaml' does not exist"), std::string::npos) << r.err;
  pbcli::write_file(tmp.path + "/bad.yaml", "name: x\nwidth: 64\nheight: 48\nfx: 50\nfy: 50\n"
                                            "noise: {model: structured_light, edge_dropout_rate: 2}\n");
  r = pbcli::run("twin empty --sensor bad.yaml --out t", tmp.path);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("edge_dropout_rate"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("bad.yaml"), std::string::npos) << r.err;
  make_real(tmp.path, 1);
  r = pbcli::run("sensor-fit real --out f --base synthetic --no-plots", tmp.path);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--base"), std::string::npos) << r.err;
  pbcli::write_file(tmp.path + "/exp.yaml",
                    "object: all\nscenes:\n  - {name: t, twin_of: nosuch, twin: {sensor: astra}}\n"
                    "descriptors: [ppf]\n");
  r = pbcli::run("run exp.yaml --out res", tmp.path);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("twin_of"), std::string::npos) << r.err;
  pbcli::write_file(tmp.path + "/exp2.yaml",
                    "object: all\nscenes:\n  - {name: r, dataset: \"${POSEBENCH_NO_SUCH_VARIABLE}/x\"}\n"
                    "descriptors: [ppf]\n");
  r = pbcli::run("run exp2.yaml --out res2", tmp.path);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("POSEBENCH_NO_SUCH_VARIABLE is not set"), std::string::npos) << r.err;
}
