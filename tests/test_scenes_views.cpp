// Training views: viewpoint layouts (1 side view, ring of 8, ring + 4 below,
// Fibonacci sphere) and clouds that lie on the model at T_cam_model.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "core/error.h"
#include "models/procedural.h"
#include "scenes/views.h"
#include "scenes_test_util.h"

using namespace pb;

TEST(TrainingViews, Layouts) {
  ViewSettings s;
  s.views = 1;
  auto d = view_directions(s);
  ASSERT_EQ(d.size(), 1u);
  EXPECT_NEAR(d[0].z(), 0.0, 1e-12);  // from the side: no top, no bottom
  s.views = 8;
  d = view_directions(s);
  ASSERT_EQ(d.size(), 8u);
  for (const auto& v : d) EXPECT_NEAR(std::asin(v.z()) * 180 / M_PI, s.elevation_deg, 1e-9);
  s.views = 12;
  d = view_directions(s);
  ASSERT_EQ(d.size(), 12u);
  int below = 0;
  for (const auto& v : d) below += v.z() < 0;
  EXPECT_EQ(below, 4);
  s.views = 40;
  d = view_directions(s);
  ASSERT_EQ(d.size(), 40u);
  // Evenly spread: every view has a neighbour within 45 deg, none closer than 15 deg.
  for (size_t i = 0; i < d.size(); ++i) {
    double best = 180;
    for (size_t j = 0; j < d.size(); ++j)
      if (i != j) best = std::min(best, std::acos(std::clamp(d[i].dot(d[j]), -1.0, 1.0)) * 180 / M_PI);
    EXPECT_LT(best, 45);
    EXPECT_GT(best, 15);
  }
  s.views = 0;
  EXPECT_THROW(view_directions(s), InputError);
}

TEST(TrainingViews, CloudsLieOnTheModel) {
  const Mesh mesh = make_ls5();
  ViewSettings s;
  s.views = 12;
  s.resolution = 128;
  const auto views = render_training_views(mesh, s);
  ASSERT_EQ(views.size(), 12u);
  pbtest::MeshDistance md(mesh, 10.0);
  const auto dirs = view_directions(s);
  for (size_t i = 0; i < views.size(); ++i) {
    const auto& v = views[i];
    EXPECT_EQ(v.cloud.width, 128);
    EXPECT_EQ(v.cloud.points.size(), 128u * 128u);
    // The camera sits along its direction, looking at the model origin.
    const Pose T_model_cam = v.T_cam_model.inverse();
    EXPECT_NEAR(T_model_cam.t.normalized().dot(dirs[i]), 1.0, 1e-9);
    EXPECT_NEAR((v.T_cam_model * Vec3::Zero()).head<2>().norm(), 0.0, 1e-6);
    std::vector<double> dist;
    for (const auto& p : v.cloud.points)
      if (std::isfinite(p.z())) dist.push_back(md.distance(T_model_cam * p.cast<double>()));
    ASSERT_GT(dist.size(), 500u) << "view " << i;
    EXPECT_LT(pbtest::percentile(dist, 0.5), 0.01) << "view " << i;
    EXPECT_LT(pbtest::percentile(dist, 1.0), 0.05) << "view " << i;
    // The whole model is in view: no model pixel on the image border.
    for (int u = 0; u < 128; ++u) {
      EXPECT_EQ(v.depth.at(u, 0), 0.f);
      EXPECT_EQ(v.depth.at(u, 127), 0.f);
    }
  }
}

// views.follow_scene: the ring and the single view at the middle of the
// scene set's camera elevation range; a set without that range is an input
// error naming posebench_scene.json and the field.
TEST(TrainingViews, FollowSceneTakesTheSceneSetsElevation) {
  const std::string dir = pbtest::temp_dir("follow_scene");
  const auto write = [&](const std::string& text) {
    std::ofstream(dir + "/posebench_scene.json") << text;
  };
  ViewSettings s;
  s.views = 8;
  EXPECT_EQ(views_for_scene_set(s, dir).elevation_deg, 20.0);  // follow_scene off: unchanged, no file read
  s.follow_scene = true;
  try {
    views_for_scene_set(s, dir);
    ADD_FAILURE() << "no posebench_scene.json: expected an InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("posebench_scene.json"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("views.follow_scene"), std::string::npos) << e.what();
  }
  write(R"({"settings": {"camera": {"distance_mm": [600, 1500], "elevation_deg": [30, 70]}}})");
  const ViewSettings r = views_for_scene_set(s, dir);
  EXPECT_EQ(r.elevation_deg, 50.0);
  EXPECT_EQ(r.side_elevation_deg, 50.0);
  EXPECT_EQ(r.below_elevation_deg, s.below_elevation_deg);
  EXPECT_FALSE(r.follow_scene);
  for (const auto& v : view_directions(r)) EXPECT_NEAR(std::asin(v.z()) * 180 / M_PI, 50.0, 1e-9);
  ViewSettings one = s;
  one.views = 1;
  const auto d1 = view_directions(views_for_scene_set(one, dir));
  ASSERT_EQ(d1.size(), 1u);
  EXPECT_NEAR(std::asin(d1[0].z()) * 180 / M_PI, 50.0, 1e-9);
  for (const char* bad : {R"({"settings": {"camera": {}}})", R"({"settings": {"camera": {"elevation_deg": [70]}}})",
                          R"({"settings": {"camera": {"elevation_deg": [70, 30]}}})", "{not json"}) {
    write(bad);
    try {
      views_for_scene_set(s, dir);
      ADD_FAILURE() << bad << ": expected an InputError";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("posebench_scene.json"), std::string::npos) << e.what();
    }
  }
  std::filesystem::remove_all(dir);
}
