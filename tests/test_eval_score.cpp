// Scoring a BOP results file (eval/score.h) on a small dataset the test
// writes itself: estimates with known errors give exactly those errors and
// recalls, the toolkit's target rules (inst_count most visible GTs, top
// inst_count estimates by score) hold, and bad targets are named.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "core/error.h"
#include "core/rotation.h"
#include "eval/bop_csv.h"
#include "eval/score.h"
#include "io/bop.h"
#include "io/mesh_io.h"
#include "io/png.h"
#include "models/procedural.h"
#include "render/renderer.h"
#include "temp_dir.h"

using namespace pb;
namespace fs = std::filesystem;

namespace {

double diameter_of(const Mesh& m) {
  double d = 0;
  for (const Vec3f& a : m.vertices)
    for (const Vec3f& b : m.vertices) d = std::max(d, static_cast<double>((a - b).norm()));
  return d;
}

Pose pose(double rx, double ry, double x, double y, double z) {
  Pose p;
  p.R = (Eigen::AngleAxisd(rx, Vec3::UnitX()) * Eigen::AngleAxisd(ry, Vec3::UnitY())).toRotationMatrix();
  p.t = Vec3(x, y, z);
  return p;
}

// One scene (test/000001) of two 320x240 images:
//   image 1: object 1 at P1;
//   image 2: object 1 at A (visib_fract 0.5) and at B (0.9), object 2 at C.
struct Dataset {
  pbtest::TempDir tmp{"score"};
  std::string root = tmp / "ds";
  Mesh box = make_box(60, 40, 30), cyl = make_cylinder(20, 80, 24);
  double d1 = diameter_of(box), d2 = diameter_of(cyl);
  Intrinsics K = Intrinsics::from_K((Mat3() << 300, 0, 159.5, 0, 300, 119.5, 0, 0, 1).finished(), 320, 240);
  Pose P1 = pose(0.3, 0.2, 10, -5, 600), A = pose(0.1, 0.5, -80, 0, 700), B = pose(-0.4, 0.1, 70, 20, 650),
       C = pose(1.2, 0.0, 0, -60, 800);

  Dataset() {
    fs::create_directories(root + "/models");
    write_ply(root + "/models/obj_000001.ply", box);
    write_ply(root + "/models/obj_000002.ply", cyl);
    std::map<int, ModelInfo> info;
    info[1].obj_id = 1;
    info[1].diameter = d1;
    info[2].obj_id = 2;
    info[2].diameter = d2;
    write_models_info(root + "/models/models_info.json", info);
    write_camera_json(root + "/camera.json", K, 1.0);
    SceneInfo s;
    s.scene_id = 1;
    add_image(s, 1, {{1, P1}}, {1.0});
    add_image(s, 2, {{1, A}, {1, B}, {2, C}}, {0.5, 0.9, 0.7});
    write_scene_json(scene_dir(), s);
  }
  std::string scene_dir() const { return root + "/test/000001"; }

  void add_image(SceneInfo& s, int im_id, const std::vector<std::pair<int, Pose>>& gts,
                 const std::vector<double>& visib) {
    ImageInfo im;
    im.im_id = im_id;
    im.K = K;
    std::vector<RenderItem> items;
    for (size_t i = 0; i < gts.size(); ++i) {
      im.gt.push_back(GtObject{gts[i].first, gts[i].second});
      GtInfo gi;
      gi.visib_fract = visib[i];
      im.gt_info.push_back(gi);
      items.push_back(RenderItem{gts[i].first == 1 ? &box : &cyl, gts[i].second, static_cast<int>(i)});
    }
    DepthRenderer r(K);
    fs::create_directories(scene_dir() + "/depth");
    write_depth_png(bop_depth_path(scene_dir(), im_id), r.render(items).depth, 1.0);
    s.images[im_id] = im;
  }

  // The MSPD of `est` against `gt`, straight from the definition (no symmetry).
  double mspd(const Mesh& m, const Pose& est, const Pose& gt) const {
    double e = 0;
    for (const Vec3f& v : m.vertices) {
      const Vec3 x = v.cast<double>();
      e = std::max(e, (K.project(est.R * x + est.t) - K.project(gt.R * x + gt.t)).norm());
    }
    return e;
  }
};

BopResultRow row(int im_id, int obj_id, double score, const Pose& T) {
  BopResultRow r;
  r.scene_id = 1;
  r.im_id = im_id;
  r.obj_id = obj_id;
  r.score = score;
  r.T_cam_model = T;
  r.time_s = 0.25 * im_id;
  return r;
}

void write_targets(const std::string& path, const std::string& json) { std::ofstream(path) << json; }

// Number of thresholds th with error < th.
int passed(double error, const std::vector<double>& thresholds) {
  int n = 0;
  for (double th : thresholds) n += error < th;
  return n;
}

}  // namespace

TEST(EvalScore, KnownErrorsGiveThoseErrorsAndRecalls) {
  Dataset ds;
  const Vec3 shift(0.12 * ds.d1, 0, 0);  // image 1: the estimate 0.12 d off along x
  Pose P1e = ds.P1;
  P1e.t += shift;
  const std::string csv = ds.tmp / "mine_ds-test.csv";
  write_bop_results_csv(csv, {row(1, 1, 0.7, P1e),
                              row(2, 1, 0.9, ds.B), row(2, 1, 0.8, ds.A),  // both instances, exactly
                              row(2, 1, 0.1, pose(0, 0, 0, 0, 2000)),      // third of two: not scored
                              row(2, 7, 0.5, ds.C)});                      // no such target object
  write_targets(ds.root + "/test_targets_bop19.json",
                R"([{"scene_id": 1, "im_id": 1, "obj_id": 1, "inst_count": 1},
                    {"scene_id": 1, "im_id": 2, "obj_id": 1, "inst_count": 2},
                    {"scene_id": 1, "im_id": 2, "obj_id": 2, "inst_count": 1}])");
  ScoreSettings s;
  s.dataset = ds.root;
  s.results = csv;
  const ScoreResult r = score_bop_results(s);

  EXPECT_EQ(r.split, "test");
  EXPECT_EQ(r.method, "mine");
  EXPECT_EQ(r.rows, 5);
  EXPECT_EQ(r.rows_scored, 3);
  EXPECT_EQ(r.rows_not_target, 1);
  EXPECT_EQ(r.images, 2);
  EXPECT_EQ(r.total.targets, 4);
  EXPECT_DOUBLE_EQ(r.average_time_s, (0.25 + 0.5) / 2);

  ASSERT_EQ(r.errors.size(), 3u);
  // Line 2 of the file (after the header): image 1, against its one GT.
  EXPECT_EQ(r.errors[0].line, 2);
  ASSERT_EQ(r.errors[0].pairs.size(), 1u);
  const double mspd1 = ds.mspd(ds.box, P1e, ds.P1);
  EXPECT_NEAR(r.errors[0].pairs[0].mssd_mm, shift.norm(), 1e-9);
  EXPECT_NEAR(r.errors[0].pairs[0].mspd_px, mspd1, 1e-9);
  // Lines 3 and 4: exact estimates of B and A, each against both instances.
  EXPECT_EQ(r.errors[1].line, 3);
  ASSERT_EQ(r.errors[1].pairs.size(), 2u);
  EXPECT_EQ(r.errors[1].pairs[1].gt_id, 1);
  EXPECT_NEAR(r.errors[1].pairs[1].mssd_mm, 0.0, 1e-9);
  EXPECT_GT(r.errors[1].pairs[0].mssd_mm, 100.0);
  EXPECT_NEAR(r.errors[2].pairs[0].mssd_mm, 0.0, 1e-9);
  for (const ScoredEstimate& e : r.errors)
    for (const ScoredPair& p : e.pairs) EXPECT_EQ(p.vsd.size(), bop19_vsd_taus().size());
  // VSD of an exact estimate is 0 at every tau.
  for (double v : r.errors[1].pairs[1].vsd) EXPECT_EQ(v, 0.0);

  // Recalls: targets P1, A, B (found at every threshold but P1's) and C (missed).
  const auto mssd_th = bop19_mssd_thresholds();
  for (size_t i = 0; i < mssd_th.size(); ++i)
    EXPECT_DOUBLE_EQ(r.total.recall_mssd[i], (2.0 + (0.12 < mssd_th[i])) / 4) << mssd_th[i];
  EXPECT_DOUBLE_EQ(r.total.ar_mssd, (2.0 * 10 + passed(0.12, mssd_th)) / 40);
  const double mspd_norm = mspd1 * 640.0 / 320.0;
  EXPECT_DOUBLE_EQ(r.total.ar_mspd, (2.0 * 10 + passed(mspd_norm, bop19_mspd_thresholds())) / 40);
  // Per object: object 2 has one target and no estimate.
  EXPECT_EQ(r.per_object.at(1).targets, 3);
  EXPECT_EQ(r.per_object.at(2).targets, 1);
  EXPECT_EQ(r.per_object.at(2).ar_mssd, 0.0);
  EXPECT_EQ(r.per_object.at(2).ar_vsd, 0.0);  // scored with VSD: a missed target is 0, not "no VSD"
  EXPECT_EQ(r.per_object.at(2).ar, 0.0);
  EXPECT_DOUBLE_EQ(r.per_object.at(1).ar_mssd, (2.0 * 10 + passed(0.12, mssd_th)) / 30);
}

// inst_count 1 of two instances: only the most visible (B) is a target, and
// only the best-scored estimate counts, even when it sits on the other one.
TEST(EvalScore, InstCountPicksTheMostVisibleGtAndTheTopEstimates) {
  Dataset ds;
  const std::string targets = ds.tmp / "targets.json";
  write_targets(targets, R"([{"scene_id": 1, "im_id": 2, "obj_id": 1, "inst_count": 1}])");
  ScoreSettings s;
  s.dataset = ds.root;
  s.targets = targets;
  s.vsd = false;
  s.results = ds.tmp / "a_ds-test.csv";
  write_bop_results_csv(s.results, {row(2, 1, 0.9, ds.A), row(2, 1, 0.8, ds.B)});
  ScoreResult r = score_bop_results(s);
  EXPECT_EQ(r.total.targets, 1);
  EXPECT_EQ(r.rows_scored, 1);
  EXPECT_EQ(r.total.ar_mssd, 0.0);  // the top estimate is on A, which is no target
  EXPECT_TRUE(std::isnan(r.total.ar_vsd));
  EXPECT_DOUBLE_EQ(r.total.ar, 0.5 * (r.total.ar_mssd + r.total.ar_mspd));

  write_bop_results_csv(s.results, {row(2, 1, 0.8, ds.A), row(2, 1, 0.9, ds.B)});
  r = score_bop_results(s);
  EXPECT_EQ(r.total.ar_mssd, 1.0);
  EXPECT_EQ(r.total.ar_mspd, 1.0);
}

// Without a targets file every GT instance of the split is a target.
TEST(EvalScore, WithoutTargetsEveryGtIsATarget) {
  Dataset ds;
  ScoreSettings s;
  s.dataset = ds.root;
  s.vsd = false;
  s.results = ds.tmp / "a_ds-test.csv";
  write_bop_results_csv(s.results, {row(1, 1, 1, ds.P1), row(2, 2, 1, ds.C)});
  const ScoreResult r = score_bop_results(s);
  EXPECT_EQ(r.total.targets, 4);
  EXPECT_DOUBLE_EQ(r.total.ar_mssd, 0.5);
  EXPECT_EQ(r.targets_source, "every GT instance of split test");
}

TEST(EvalScore, BadInputIsNamed) {
  Dataset ds;
  ScoreSettings s;
  s.dataset = ds.root;
  s.vsd = false;
  auto field = [&]() -> std::string {
    try {
      score_bop_results(s);
    } catch (const InputError& e) {
      return e.file() + " | " + e.field();
    }
    return "<no error>";
  };
  // A name without the convention and no split given.
  s.results = ds.tmp / "results.csv";
  write_bop_results_csv(s.results, {row(1, 1, 1, ds.P1)});
  EXPECT_EQ(field(), s.results + " | file name");
  s.split = "test";
  EXPECT_EQ(field(), "<no error>");
  // An unknown split.
  s.split = "val";
  EXPECT_EQ(field(), ds.root + " | split");
  s.split = "";
  // An empty file.
  s.results = ds.tmp / "e_ds-test.csv";
  std::ofstream(s.results) << "scene_id,im_id,obj_id,score,R,t,time\n";
  EXPECT_EQ(field(), s.results + " | ");
  // A target image or object the dataset lacks.
  write_bop_results_csv(s.results, {row(1, 1, 1, ds.P1)});
  s.targets = ds.tmp / "t.json";
  write_targets(s.targets, R"([{"scene_id": 1, "im_id": 5, "obj_id": 1, "inst_count": 1}])");
  EXPECT_EQ(field(), s.targets + " | scene 1 image 5");
  write_targets(s.targets, R"([{"scene_id": 1, "im_id": 1, "obj_id": 9, "inst_count": 1}])");
  EXPECT_EQ(field(), s.targets + " | scene 1 image 1 obj_id");
  write_targets(s.targets, R"([{"scene_id": 4, "im_id": 1, "obj_id": 1, "inst_count": 1}])");
  EXPECT_EQ(field(), s.targets + " | scene 4");
}
