// posebench generate: byte-identical output for the same config and seed,
// different scenes for another seed, the BOP layout and the default folder.
#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <tuple>

#include "cli_test_util.h"
#include "io/bop.h"

namespace fs = std::filesystem;

namespace {

const char* kConfig = R"(scenario: table
seed: 5
images: 3
sensor: synthetic
noise: {model: gaussian, sigma_mm: 1.0}
target: ls5
distractors: {pool: [milk_carton, boletus, box_small, cylinder], count: [3, 5]}
occlusion: {visib_fract: [0.4, 0.9], probability: 0.5}
)";

// Relative path -> bytes of every file under dir.
std::map<std::string, std::string> tree(const std::string& dir) {
  std::map<std::string, std::string> t;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) t[fs::relative(e.path(), dir).string()] = pbcli::slurp(e.path().string());
  return t;
}

}  // namespace

TEST(CliGenerate, SameSeedSameBytesOtherSeedOtherScenes) {
  pbcli::TempDir tmp;
  pbcli::write_file(tmp.path + "/small_table.yaml", kConfig);
  auto a = pbcli::run("generate small_table.yaml --out a --quiet --threads 1", tmp.path);
  ASSERT_EQ(a.code, 0) << a.err;
  EXPECT_NE(a.out.find("3 images"), std::string::npos) << a.out;
  EXPECT_NE(a.out.find("depth preview"), std::string::npos) << a.out;
  auto b = pbcli::run("generate small_table.yaml --out b --quiet --threads 2", tmp.path);  // any thread count
  ASSERT_EQ(b.code, 0) << b.err;
  const auto ta = tree(tmp.path + "/a"), tb = tree(tmp.path + "/b");
  ASSERT_EQ(ta.size(), tb.size());
  for (const auto& [path, bytes] : ta) {
    ASSERT_TRUE(tb.count(path)) << path;
    EXPECT_TRUE(bytes == tb.at(path)) << path << " differs";
  }
  // The BOP layout.
  for (const char* f : {"camera.json", "models/models_info.json", "test/000001/scene_camera.json",
                        "test/000001/scene_gt.json", "test/000001/scene_gt_info.json",
                        "test/000001/depth/000000.png", "test/000001/depth/000002.png",
                        "test/000001/mask_visib/000000_000000.png", "posebench_scene.json", "depth_preview.png"})
    EXPECT_TRUE(ta.count(f)) << f;
  EXPECT_TRUE(ta.count("models/obj_000002.ply"));  // ls5
  const pb::BopDataset ds(tmp.path + "/a");
  const auto scene = ds.load_scene("test", 1);
  EXPECT_EQ(scene.images.size(), 3u);
  EXPECT_EQ(scene.images.at(0).gt.at(0).obj_id, 2);
  // The test targets: every object instance visible at least 10% (BOP 2019),
  // so `object: all` runs every object of the set.
  ASSERT_TRUE(ta.count("test_targets_bop19.json"));
  std::map<std::tuple<int, int>, int> expected, listed;  // (im_id, obj_id) -> instances
  for (const auto& [im, info] : scene.images)
    for (size_t k = 0; k < info.gt.size(); ++k)
      if (info.gt_info.at(k).visib_fract >= 0.1) ++expected[{im, info.gt[k].obj_id}];
  for (const auto& t : pb::read_test_targets(tmp.path + "/a/test_targets_bop19.json")) {
    EXPECT_EQ(t.scene_id, 1);
    listed[{t.im_id, t.obj_id}] = t.inst_count;
  }
  EXPECT_EQ(listed, expected);
  EXPECT_GE(expected.size(), 3u);  // the target in each of the 3 images, at least

  auto c = pbcli::run("generate small_table.yaml --out c --seed 6 --quiet", tmp.path);
  ASSERT_EQ(c.code, 0) << c.err;
  const auto tc = tree(tmp.path + "/c");
  for (const char* f : {"test/000001/depth/000000.png", "test/000001/depth/000001.png", "test/000001/scene_gt.json"})
    EXPECT_FALSE(ta.at(f) == tc.at(f)) << f << " is the same for another seed";
  // Nothing left over.
  for (const char* d : {"a.partial", "b.partial", "c.partial"}) EXPECT_FALSE(fs::exists(tmp.path + "/" + d));
}

TEST(CliGenerate, DefaultOutputFolderFromConfigName) {
  pbcli::TempDir tmp;
  pbcli::write_file(tmp.path + "/configs/tiny.yaml",
                    "scenario: warehouse\nseed: 3\nimages: 1\nnoise: none\n"
                    "sensor: {name: synthetic, max_range_mm: 12000, depth_scale: 0.2}\n");
  auto r = pbcli::run("generate configs/tiny.yaml --quiet", tmp.path);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::exists(tmp.path + "/scenes/tiny/posebench_scene.json"));
  EXPECT_TRUE(fs::exists(tmp.path + "/scenes/tiny/test/000001/depth/000000.png"));
  // A second run replaces the scene set.
  r = pbcli::run("generate configs/tiny.yaml --quiet --images 2", tmp.path);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::exists(tmp.path + "/scenes/tiny/test/000001/depth/000001.png"));
  EXPECT_FALSE(fs::exists(tmp.path + "/scenes/tiny.old"));
}
