// Scene sets of a few set-ups (scene config `setups`): images of one set-up
// show the same objects where they stood, seen from another camera; images
// of different set-ups differ; any image alone is the same; bad values are
// InputErrors naming the file and the field.
#include <gtest/gtest.h>

#include <string>

#include "core/error.h"
#include "core/yaml.h"
#include "scenes/generator.h"
#include "scenes/scene_config.h"

using namespace pb;

namespace {

const char* kTable = R"(
scenario: table
scene_id: 2
seed: 9
images: 4
sensor: synthetic
noise: none
target: ls5
distractors: {pool: [milk_carton, boletus, box_small, cylinder], count: [3, 6]}
setups: 2
)";

SceneSettings settings_from(const std::string& yaml) {
  SceneSettings s = parse_scene_settings(YamlNode::load_string(yaml, "setups.yaml"));
  s.name = "test";
  return s;
}

// Object k of an image in the world frame.
Pose world_pose(const GeneratedImage& img, size_t k) { return img.T_world_cam * img.info.gt[k].T_cam_model; }

bool same_pose(const Pose& a, const Pose& b) { return a.R.isApprox(b.R, 1e-9) && (a.t - b.t).norm() < 1e-6; }

}  // namespace

TEST(SceneSetups, ImagesOfOneSetUpShowTheSameObjectsFromAnotherCamera) {
  SceneGenerator gen(settings_from(kTable));
  const GeneratedImage a = gen.generate(0), b = gen.generate(1), c = gen.generate(2);
  ASSERT_FALSE(a.info.gt.empty());
  ASSERT_FALSE(c.info.gt.empty());
  // Set-up 0 (images 0 and 2): the target where it stood, another camera.
  EXPECT_TRUE(same_pose(world_pose(a, 0), world_pose(c, 0)));
  EXPECT_GT((a.T_world_cam.t - c.T_world_cam.t).norm(), 1.0);
  EXPECT_NE(a.depth.z, c.depth.z);
  // Every other object image 2 sees stands where image 0's set-up put it.
  int shared = 0;
  for (size_t j = 1; j < c.info.gt.size(); ++j) {
    bool found = false;
    for (size_t i = 1; i < a.info.gt.size(); ++i)
      found = found || (a.info.gt[i].obj_id == c.info.gt[j].obj_id && same_pose(world_pose(a, i), world_pose(c, j)));
    if (found) ++shared;
    // An object out of image 0's view is still one of the set-up's: not checked here.
  }
  EXPECT_GE(shared, 1);
  // Set-up 1 (image 1) is another arrangement.
  EXPECT_FALSE(same_pose(world_pose(a, 0), world_pose(b, 0)));
}

TEST(SceneSetups, AnImageAloneIsTheSameAndNoSetUpsKeepsTheOldImages) {
  const SceneSettings s = settings_from(kTable);
  SceneGenerator all(s), alone(s);
  all.generate(0);
  all.generate(1);
  const GeneratedImage third = all.generate(2);
  EXPECT_EQ(alone.generate(2).depth.z, third.depth.z);

  std::string plain = kTable;
  plain.replace(plain.find("setups: 2"), 9, "setups: 0");
  const SceneSettings p = settings_from(plain);
  EXPECT_EQ(p.setups, 0);
  EXPECT_EQ(scene_settings_json(p).find("\"setups\""), std::string::npos);  // older sets' json unchanged
  SceneGenerator g0(p), g1(p);
  const GeneratedImage i0 = g0.generate(0), i2 = g1.generate(2);
  EXPECT_FALSE(same_pose(world_pose(i0, 0), world_pose(i2, 0)));  // a new layout per image
}

TEST(SceneSetups, BadSetUpsNameTheField) {
  for (const char* extra : {"occlusion: {visib_fract: [0.4, 0.9]}\n", "table: {wall_distance_mm: 500}\n"}) {
    try {
      settings_from(std::string(kTable) + extra);
      ADD_FAILURE() << "no InputError with " << extra;
    } catch (const InputError& e) {
      EXPECT_EQ(e.file(), "setups.yaml");
      EXPECT_NE(std::string(e.what()).find("setups"), std::string::npos) << e.what();
    }
  }
  std::string many = kTable;
  many.replace(many.find("setups: 2"), 9, "setups: 5");
  try {
    settings_from(many);
    ADD_FAILURE() << "no InputError for more set-ups than images";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("at most images"), std::string::npos) << e.what();
  }
}
