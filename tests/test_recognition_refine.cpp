// Refinement methods (thesis 3.1.7; issue 3 "must show"): each
// method, started from the ground truth perturbed by 10 degrees and 20 mm
// (random axis and direction, seeded) on 20 generated table images of an
// asymmetric object, must converge to within 5 mm and 2 degrees in at least
// 90% of them; NDT is held to what it was measured to reach, minus a margin.
// Also: determinism (same inputs -> same pose bits), unknown names, empty
// inputs, YAML parsing, the methods built by name with their own settings
// subsection.
#include <gtest/gtest.h>

#include <tuple>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>

#include "core/error.h"
#include "core/hash.h"
#include "core/yaml.h"
#include "recognition/kdtree.h"
#include "recognition/refine/refine.h"
#include "recognition/registry.h"
#include "recognition/settings.h"
#include "test_recognition_refine_scenes.h"

namespace pb {
namespace {

constexpr int kCases = 20;
constexpr uint64_t kSeed = 20160601;

class RefineCases : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (!cases_.empty()) return;
    const Mesh object = refine_test::asymmetric_object();
    for (int i = 0; i < kCases; ++i) cases_.push_back(refine_test::make_case(object, i, kSeed));
  }
  static std::vector<refine_test::Case> cases_;
};
std::vector<refine_test::Case> RefineCases::cases_;

struct Rate {
  int ok = 0;
  double max_t_ok = 0, max_r_ok = 0;
  double sum_t = 0, sum_r = 0;  // over every case
};

Rate run_method(const std::vector<refine_test::Case>& cases, const std::string& method, const RefineSettings& s) {
  Rate rate;
  for (size_t i = 0; i < cases.size(); ++i) {
    const auto& c = cases[i];
    const RefineResult r = refine_pose(method, c.model, c.scene, c.init, s, derive_seed(kSeed, {7, i}));
    const double et = refine_test::translation_error(r.T_cam_model, c.gt);
    const double er = refine_test::rotation_error_deg(r.T_cam_model, c.gt);
    const bool ok = et < 5.0 && er < 2.0;
    rate.sum_t += et;
    rate.sum_r += er;
    std::printf("  %-9s case %2zu: scene %4zu model %4zu  t %6.2f mm  R %5.2f deg  it %2d conv %d fit %6.2f %s\n",
                method.c_str(), i, c.scene.size(), c.model.size(), et, er, r.iterations, r.converged ? 1 : 0,
                registration_fitness(c.model, c.scene, r.T_cam_model, s.max_correspondence_mm), ok ? "" : "MISS");
    if (ok) {
      ++rate.ok;
      rate.max_t_ok = std::max(rate.max_t_ok, et);
      rate.max_r_ok = std::max(rate.max_r_ok, er);
    }
  }
  std::printf("%-9s converged within 5 mm / 2 deg: %d of %zu (mean error %.2f mm, %.2f deg; worst success: %.2f mm, "
              "%.2f deg)\n",
              method.c_str(), rate.ok, cases.size(), rate.sum_t / cases.size(), rate.sum_r / cases.size(),
              rate.max_t_ok, rate.max_r_ok);
  return rate;
}

TEST_F(RefineCases, InitialPosesArePerturbed) {
  ASSERT_EQ(cases_.size(), static_cast<size_t>(kCases));
  for (const auto& c : cases_) {
    EXPECT_NEAR(refine_test::translation_error(c.init, c.gt), 20.0, 1e-6);
    EXPECT_NEAR(refine_test::rotation_error_deg(c.init, c.gt), 10.0, 1e-6);
    EXPECT_GT(c.scene.size(), 100u);
    EXPECT_GT(c.model.size(), 100u);
  }
  // Without refinement no case is within the thresholds.
  EXPECT_EQ(run_method(cases_, "none", RefineSettings{}).ok, 0);
}

TEST_F(RefineCases, IcpConverges) { EXPECT_GE(run_method(cases_, "icp", RefineSettings{}).ok, 18); }

// A random half of the ~1000 model view points (fewer points make the source
// as sparse as the scene: 100 points gave 9 of 20, 300 gave 16 to 19).
TEST_F(RefineCases, IcpOnRandomSubsetConverges) {
  RefineSettings s;
  s.icp.sample_points = 500;
  EXPECT_GE(run_method(cases_, "icp", s).ok, 17);
}

// Point-to-plane on a random subset (the warehouse's speed setting), a fifth
// of the source: measured 20 of 20 within 5 mm / 2 deg, mean error 0.39 mm
// (0.25 mm on every point).
TEST_F(RefineCases, IcpPlaneOnRandomSubsetConverges) {
  RefineSettings s;
  s.icp.sample_points = 200;
  const Rate sub = run_method(cases_, "icp_plane", s), all = run_method(cases_, "icp_plane", RefineSettings{});
  EXPECT_GE(sub.ok, all.ok - 1);
  EXPECT_LT(sub.sum_t / cases_.size(), all.sum_t / cases_.size() + 0.5);
  // The subset is drawn from the seed: another seed, another pose.
  const auto& c = cases_[0];
  const RefineResult a = refine_pose("icp_plane", c.model, c.scene, c.init, s, 1);
  const RefineResult b = refine_pose("icp_plane", c.model, c.scene, c.init, s, 2);
  EXPECT_NE(a.T_cam_model.t, b.T_cam_model.t);
}

// Coarse to fine (icp.coarse_points): a third of the ~1000 model points
// first, then all of them. Held to the one-stage run on every point: at most
// one case fewer within 5 mm / 2 deg and mean errors within 0.3 mm and 0.3
// degrees; never more than max_iterations in total. A coarse subset at least
// as large as the source is the one-stage run, bit for bit.
TEST_F(RefineCases, CoarseToFineKeepsTheOneStageAccuracy) {
  RefineSettings one, two, big;
  one.icp.coarse_points = 0;
  two.icp.coarse_points = 300;
  big.icp.coarse_points = 100000;
  for (const std::string method : {"icp", "icp_plane"}) {
    SCOPED_TRACE(method);
    const Rate a = run_method(cases_, method, one), b = run_method(cases_, method, two);
    EXPECT_GE(b.ok, a.ok - 1);
    EXPECT_LT(b.sum_t / cases_.size(), a.sum_t / cases_.size() + 0.3);
    EXPECT_LT(b.sum_r / cases_.size(), a.sum_r / cases_.size() + 0.3);
    for (size_t i = 0; i < cases_.size(); ++i) {
      const auto& c = cases_[i];
      ASSERT_GT(c.model.size(), 300u);
      const RefineResult r2 = refine_pose(method, c.model, c.scene, c.init, two, 5);
      EXPECT_LE(r2.iterations, two.max_iterations);
      const RefineResult r1 = refine_pose(method, c.model, c.scene, c.init, one, 5);
      const RefineResult rb = refine_pose(method, c.model, c.scene, c.init, big, 5);
      EXPECT_EQ(std::memcmp(r1.T_cam_model.t.data(), rb.T_cam_model.t.data(), sizeof(double) * 3), 0) << i;
      EXPECT_EQ(r1.iterations, rb.iterations) << i;
    }
  }
}

TEST_F(RefineCases, IcpLmConverges) { EXPECT_GE(run_method(cases_, "icp_lm", RefineSettings{}).ok, 18); }

TEST_F(RefineCases, IcpPlaneConverges) { EXPECT_GE(run_method(cases_, "icp_plane", RefineSettings{}).ok, 18); }

TEST_F(RefineCases, GicpConverges) { EXPECT_GE(run_method(cases_, "gicp", RefineSettings{}).ok, 18); }

TEST_F(RefineCases, GicpWithPclCovariancesConverges) {
  RefineSettings s;
  s.gicp.covariances_from_normals = false;
  EXPECT_GE(run_method(cases_, "gicp", s).ok, 18);
}

TEST_F(RefineCases, NdtConverges) { EXPECT_GE(run_method(cases_, "ndt", RefineSettings{}).ok, 18); }

// The same cases with the model view at the scene's 10 mm voxel: point-to-
// point ICP is then limited by the sampling (see refine_test::CaseOptions);
// held to what was measured, minus a margin.
TEST(Refine, PointToPointWithModelAtSceneVoxel) {
  const Mesh object = refine_test::asymmetric_object();
  refine_test::CaseOptions o;
  o.model_voxel_mm = o.preprocess.voxel_mm;
  std::vector<refine_test::Case> cases;
  for (int i = 0; i < kCases; ++i) cases.push_back(refine_test::make_case(object, i, kSeed, o));
  EXPECT_GE(run_method(cases, "icp", RefineSettings{}).ok, 12);
  EXPECT_GE(run_method(cases, "icp_plane", RefineSettings{}).ok, 18);
  EXPECT_GE(run_method(cases, "gicp", RefineSettings{}).ok, 18);
}

// The project's ICP is PCL's algorithm with the search trees built once.
// Float rounding (PCL moves its float cloud every iteration; ours maps each
// point from its original position) makes slowly creeping point-to-point
// runs stop an iteration or a few apart: measured up to 6 iterations and
// 0.46 deg apart on these cases with every model point. On a random subset
// of 150 points the paths are chaotic (one case: 40 vs 31 iterations, 3 mm
// apart), so there only the aggregate is compared. Per case (all points,
// with and without reciprocal correspondences): within 8 iterations and
// 0.5 mm / 0.6 deg of stock PCL. Over all cases, every variant: the number
// within 5 mm / 2 deg of the truth differs by at most one (measured: equal,
// except point-to-point without reciprocal correspondences, 0 vs 1 of 20:
// PCL's one success is at 1.96 deg, on the threshold), mean errors within
// 0.3 mm and 0.3 deg of PCL's (measured: within 0.13 mm and 0.28 deg, ours
// the smaller on the subset).
TEST_F(RefineCases, OwnIcpAgreesWithStockPclCaseByCase) {
  RefineSettings plain, no_recip, sub;
  plain.icp.coarse_points = 0;  // PCL's one stage
  no_recip = sub = plain;
  no_recip.reciprocal_correspondences = false;
  sub.icp.sample_points = 150;
  const std::vector<std::tuple<std::string, std::string, RefineSettings>> pairs = {
      {"icp", "icp_pcl", plain},           {"icp", "icp_pcl", no_recip},
      {"icp", "icp_pcl", sub},             {"icp_plane", "icp_plane_pcl", plain},
      {"icp_plane", "icp_plane_pcl", no_recip}};
  for (const auto& [own, pcl, s] : pairs) {
    SCOPED_TRACE(own + " reciprocal " + std::to_string(s.reciprocal_correspondences) + " subset " +
                 std::to_string(s.icp.sample_points));
    for (size_t i = 0; i < cases_.size() && s.icp.sample_points == 0; ++i) {
      const auto& c = cases_[i];
      const RefineResult a = refine_pose(own, c.model, c.scene, c.init, s, derive_seed(kSeed, {7, i}));
      const RefineResult b = refine_pose(pcl, c.model, c.scene, c.init, s, derive_seed(kSeed, {7, i}));
      EXPECT_NEAR(a.iterations, b.iterations, 8) << "case " << i;
      EXPECT_LT(refine_test::translation_error(a.T_cam_model, b.T_cam_model), 0.5) << "case " << i;
      EXPECT_LT(refine_test::rotation_error_deg(a.T_cam_model, b.T_cam_model), 0.6) << "case " << i;
    }
    const Rate ra = run_method(cases_, own, s), rb = run_method(cases_, pcl, s);
    EXPECT_NEAR(ra.ok, rb.ok, 1);
    EXPECT_NEAR(ra.sum_t / cases_.size(), rb.sum_t / cases_.size(), 0.3);
    EXPECT_NEAR(ra.sum_r / cases_.size(), rb.sum_r / cases_.size(), 0.3);
  }
}

TEST_F(RefineCases, SameInputsGiveSamePoseBits) {
  RefineSettings sub;
  sub.icp.sample_points = 100;
  const std::vector<std::pair<std::string, RefineSettings>> runs = {
      {"icp", RefineSettings{}}, {"icp", sub},  {"icp_lm", RefineSettings{}}, {"icp_plane", RefineSettings{}},
      {"gicp", RefineSettings{}}, {"ndt", RefineSettings{}}};
  for (const auto& [method, s] : runs) {
    for (size_t i = 0; i < 3; ++i) {
      const auto& c = cases_[i];
      const RefineResult a = refine_pose(method, c.model, c.scene, c.init, s, 11);
      const RefineResult b = refine_pose(method, c.model, c.scene, c.init, s, 11);
      EXPECT_EQ(std::memcmp(a.T_cam_model.R.data(), b.T_cam_model.R.data(), sizeof(double) * 9), 0) << method;
      EXPECT_EQ(std::memcmp(a.T_cam_model.t.data(), b.T_cam_model.t.data(), sizeof(double) * 3), 0) << method;
      EXPECT_EQ(a.iterations, b.iterations) << method;
    }
  }
  // The ICP subset depends on the seed.
  const auto& c = cases_[0];
  const RefineResult a = refine_pose("icp", c.model, c.scene, c.init, sub, 11);
  const RefineResult b = refine_pose("icp", c.model, c.scene, c.init, sub, 12);
  EXPECT_NE(std::memcmp(a.T_cam_model.t.data(), b.T_cam_model.t.data(), sizeof(double) * 3), 0);
}

// Our ICP and ICP point-to-plane, bit for bit as recorded, so that a change
// meant to find the same correspondences faster shows when it does not: the
// 20 cases under the default settings, without reciprocity, on a random 100
// points, and coarse to fine from 200 points (on this toolchain: x86-64
// without FMA contraction, as the ESF fingerprints). The bytes are the pose
// and the iteration count (RefineResult carries no fitness).
TEST_F(RefineCases, OwnIcpPosesAreTheRecordedBits) {
  RefineSettings one_way, sub, coarse;
  one_way.reciprocal_correspondences = false;
  sub.icp.sample_points = 100;
  coarse.icp.coarse_points = 200;
  std::string bytes;
  for (const std::string method : {"icp", "icp_plane"})
    for (const RefineSettings& s : {RefineSettings{}, one_way, sub, coarse})
      for (size_t i = 0; i < cases_.size(); ++i) {
        const auto& c = cases_[i];
        const RefineResult r = refine_pose(method, c.model, c.scene, c.init, s, derive_seed(kSeed, {9, i}));
        bytes.append(reinterpret_cast<const char*>(r.T_cam_model.R.data()), sizeof(double) * 9);
        bytes.append(reinterpret_cast<const char*>(r.T_cam_model.t.data()), sizeof(double) * 3);
        bytes.append(reinterpret_cast<const char*>(&r.iterations), sizeof r.iterations);
      }
  EXPECT_EQ(hash_hex(bytes), "e9c306194ba5616e");
}

// registration_fitness: the mean squared distance to the nearest scene point
// over the model points within the bound, the bound squared when none is.
TEST(Refine, FitnessIsTheMeanSquaredDistanceOfThePointsWithinTheBound) {
  PointSet model, scene;
  for (int i = 0; i < 10; ++i) {
    model.points.push_back(Vec3f(100.0f * static_cast<float>(i), 0, 0));
    scene.points.push_back(Vec3f(100.0f * static_cast<float>(i), 0, i < 5 ? 2.0f : 30.0f));
  }
  scene.points.push_back(Vec3f(NAN, 0, 0));  // skipped, as the crop does
  Pose T;  // identity
  EXPECT_NEAR(registration_fitness(model, scene, T, 10.0), 4.0, 1e-6);  // the five 2 mm pairs
  EXPECT_NEAR(registration_fitness(model, scene, T, 50.0), (5 * 4.0 + 5 * 900.0) / 10, 1e-3);
  EXPECT_EQ(registration_fitness(model, scene, T, 1.0), 1.0);  // no pair within 1 mm
  T.t = Vec3(0, 0, 2);  // the first five now coincide
  EXPECT_NEAR(registration_fitness(model, scene, T, 10.0), 0.0, 1e-9);
}

// A crop tree cut from the scene's tree (refine_pose's scene_tree, what the
// pipeline passes; used when the crop holds at least half the scene) gives
// the same poses, bit for bit, as one built.
TEST_F(RefineCases, CropTreeCutFromTheSceneTreeGivesTheSamePoses) {
  const RefineSettings s;
  for (const std::string method : {"icp", "icp_plane", "gicp"})
    for (size_t i = 0; i < cases_.size(); i += 3) {
      const auto& c = cases_[i];
      Vec3 centre = Vec3::Zero();
      for (const auto& x : c.model.points) centre += c.init * x.cast<double>();
      centre /= static_cast<double>(c.model.size());
      double radius = 0;
      for (const auto& x : c.model.points) radius = std::max(radius, (c.init * x.cast<double>() - centre).norm());
      // The scene (the object's surface alone) and, far off, every other
      // point of it again: the crop is two thirds of the points.
      PointSet scene = c.scene;
      for (size_t k = 0; k < c.scene.size(); k += 2) {
        scene.points.push_back(c.scene.points[k] + Vec3f(0, 0, static_cast<float>(4 * radius)));
        scene.normals.push_back(c.scene.normals[k]);
      }
      size_t crop = 0;
      for (const auto& q : scene.points) crop += (q.cast<double>() - centre).norm() <= radius + s.max_correspondence_mm;
      ASSERT_GE(2 * crop, scene.size());  // cut, not built
      ASSERT_LT(crop, scene.size());      // with points left out
      const KdTree3 scene_tree(scene.points, 24);
      const RefineResult a = refine_pose(method, c.model, scene, c.init, s, 5);
      const RefineResult b = refine_pose(method, c.model, scene, c.init, s, 5, &scene_tree);
      EXPECT_EQ(a.T_cam_model.R, b.T_cam_model.R) << method << " case " << i;
      EXPECT_EQ(a.T_cam_model.t, b.T_cam_model.t) << method << " case " << i;
      EXPECT_EQ(a.iterations, b.iterations);
    }
  const KdTree3 wrong(std::vector<Vec3f>{Vec3f(0, 0, 0)});
  EXPECT_THROW(refine_pose("icp", cases_[0].model, cases_[0].scene, cases_[0].init, RefineSettings{}, 5, &wrong),
               std::invalid_argument);
}

TEST_F(RefineCases, NoneReturnsTheInitialPose) {
  const auto& c = cases_[0];
  const RefineResult r = refine_pose("none", c.model, c.scene, c.init, RefineSettings{}, 1);
  EXPECT_EQ(r.T_cam_model.R, c.init.R);
  EXPECT_EQ(r.T_cam_model.t, c.init.t);
  EXPECT_EQ(r.iterations, 0);
}

TEST(Refine, UnknownMethodIsAnInputError) {
  PointSet a;
  a.points.push_back(Vec3f(0, 0, 500));
  try {
    refine_pose("icp_magic", a, a, Pose{}, RefineSettings{}, 1);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "refinement");
    EXPECT_NE(std::string(e.what()).find("icp_magic"), std::string::npos);
  }
}

TEST(Refine, EmptyOrFarCloudsReturnTheInitialPose) {
  PointSet empty, some;
  for (int i = 0; i < 50; ++i) some.points.push_back(Vec3f(i, 2 * i % 7, 600 + i % 5));
  Pose init;
  init.t = Vec3(1, 2, 3);
  for (const char* m : {"icp", "icp_lm", "icp_plane", "gicp", "ndt"}) {
    for (const auto& [model, scene] : {std::make_pair(&empty, &some), std::make_pair(&some, &empty)}) {
      const RefineResult r = refine_pose(m, *model, *scene, init, RefineSettings{}, 1);
      EXPECT_EQ(r.T_cam_model.t, init.t) << m;
      EXPECT_FALSE(r.converged) << m;
    }
    // Scene far from the model at its initial pose: nothing to register.
    Pose far = init;
    far.t = Vec3(5000, 0, 0);
    const RefineResult r = refine_pose(m, some, some, far, RefineSettings{}, 1);
    EXPECT_EQ(r.T_cam_model.t, far.t) << m;
  }
}

TEST(Refine, ParseReadsEveryFieldAndRejectsBadOnes) {
  const YamlNode n = YamlNode::load_string(
      "refine:\n  max_iterations: 25\n  max_correspondence_mm: 15\n  transformation_epsilon: 1e-9\n"
      "  rotation_epsilon_deg: 0.1\n  fitness_epsilon: 1e-5\n  crop_margin_mm: 30\n  normal_neighbours: 12\n"
      "  icp: {sample_points: 200, coarse_points: 400, fine_iterations: 5}\n"
      "  ndt:\n    resolution_mm: 30\n    resolution_fraction: 0.2\n    step_size_mm: 5\n"
      "    outlier_ratio: 0.4\n    min_points_per_cell: 4\n"
      "  gicp: {correspondence_randomness: 10, covariances_from_normals: false}\n",
      "cfg.yaml");
  RefineSettings s;
  parse_section(n["refine"], s);
  EXPECT_EQ(s.max_iterations, 25);
  EXPECT_EQ(s.max_correspondence_mm, 15);
  EXPECT_EQ(s.transformation_epsilon, 1e-9);
  EXPECT_EQ(s.rotation_epsilon_deg, 0.1);
  EXPECT_EQ(s.fitness_epsilon, 1e-5);
  EXPECT_EQ(s.icp.sample_points, 200);
  EXPECT_EQ(s.icp.coarse_points, 400);
  EXPECT_EQ(s.icp.fine_iterations, 5);
  EXPECT_EQ(s.ndt.resolution_mm, 30);
  EXPECT_EQ(s.ndt.resolution_fraction, 0.2);
  EXPECT_EQ(s.ndt.step_size_mm, 5);
  EXPECT_EQ(s.ndt.outlier_ratio, 0.4);
  EXPECT_EQ(s.ndt.min_points_per_cell, 4);
  EXPECT_EQ(s.gicp.correspondence_randomness, 10);
  EXPECT_FALSE(s.gicp.covariances_from_normals);
  EXPECT_EQ(s.crop_margin_mm, 30);
  EXPECT_EQ(s.normal_neighbours, 12);

  auto fails = [](const std::string& text, const std::string& field) {
    RefineSettings t;
    try {
      parse_section(YamlNode::load_string(text, "bad.yaml")["refine"], t);
    } catch (const InputError& e) {
      EXPECT_EQ(e.file(), "bad.yaml");
      EXPECT_EQ(e.field(), field) << e.what();
      return;
    }
    ADD_FAILURE() << "no error for " << text;
  };
  fails("refine:\n  max_iterationz: 3\n", "refine.max_iterationz");
  fails("refine:\n  max_iterations: 0\n", "refine.max_iterations");
  fails("refine:\n  max_correspondence_mm: -1\n", "refine.max_correspondence_mm");
  fails("refine:\n  ndt:\n    outlier_ratio: 1.5\n", "refine.ndt.outlier_ratio");
  fails("refine:\n  ndt: {min_points_per_cell: 2}\n", "refine.ndt.min_points_per_cell");
  fails("refine:\n  icp: {sample_points: many}\n", "refine.icp.sample_points");
  fails("refine:\n  icp: {samples: 3}\n", "refine.icp.samples");
  fails("refine:\n  icp_sample_points: 200\n", "refine.icp_sample_points");  // unknown: it is icp.sample_points
}

// Each method is built by name from the registry with the common settings
// and its own subsection; "none" is no method.
TEST(Refine, MethodsAreBuiltByNameWithTheirOwnSection) {
  RefineSettings s;
  EXPECT_EQ(make_refiner("none", s), nullptr);
  EXPECT_FALSE(make_refiner("icp", s)->needs_normals());
  EXPECT_TRUE(make_refiner("icp_plane", s)->needs_normals());
  EXPECT_TRUE(make_refiner("icp_plane_pcl", s)->needs_normals());
  EXPECT_FALSE(make_refiner("ndt", s)->needs_normals());
  EXPECT_TRUE(make_refiner("gicp", s)->needs_normals());
  s.gicp.covariances_from_normals = false;
  EXPECT_FALSE(make_refiner("gicp", s)->needs_normals());
  EXPECT_THROW(make_refiner("icp2", s), InputError);
  for (const auto& e : refinement_registry())
    EXPECT_TRUE(e.section.empty() || e.section == "icp" || e.section == "gicp" || e.section == "ndt") << e.name;
}

// A nested section's lengths may be relative ("refine.ndt.resolution_mm"),
// are written back so in the JSON, nested, and resolve like the others.
TEST(Refine, NestedSectionsTakeRelativeLengths) {
  const RecognitionSettings s = parse_recognition_settings(
      YamlNode::load_string("refine:\n  ndt: {resolution_mm: 0.2d, step_size_mm: 50}\n", "cfg.yaml"));
  EXPECT_EQ(s.relative.at("refine.ndt.resolution_mm"), 0.2);
  EXPECT_EQ(s.relative.count("refine.ndt.step_size_mm"), 0u);
  const auto j = recognition_settings_json(s);
  EXPECT_EQ(j["refine"]["ndt"]["resolution_mm"], "0.2d");
  EXPECT_EQ(j["refine"]["ndt"]["step_size_mm"], 50.0);
  EXPECT_EQ(j["refine"]["icp"]["coarse_points"], 1000);
  const RecognitionSettings r = resolve_lengths(s, 100);
  EXPECT_DOUBLE_EQ(r.refine.ndt.resolution_mm, 20);
  EXPECT_DOUBLE_EQ(r.refine.ndt.step_size_mm, 50);
  EXPECT_TRUE(RecognitionSettings().relative.count("refine.ndt.step_size_mm"));
}

}  // namespace
}  // namespace pb
