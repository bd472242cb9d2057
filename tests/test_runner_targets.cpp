// BOP test-targets files (test_targets_bop19.json): read_test_targets accepts
// the BOP layout and rejects a bad entry naming the file and the entry; an
// experiment scene with `targets:` expands to exactly the images that file
// lists for the experiment's object (and to their scenes when scene_ids is
// not given); a target outside the dataset, or none for the object, is an
// InputError naming the file and the field. Configs without `targets` keep
// their hash (no new key in the canonical JSON).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <tuple>
#include <utility>

#include "core/error.h"
#include "io/bop.h"
#include "runner/experiment.h"
#include "runner/trial.h"
#include "temp_dir.h"

namespace fs = std::filesystem;

namespace {

struct Dataset {
  pbtest::TempDir tmp{"targets"};
  std::string root = tmp.path.string();
  Dataset() {
    std::map<int, pb::ModelInfo> models;
    for (int id : {1, 2}) {
      pb::ModelInfo m;
      m.obj_id = id;
      m.name = id == 1 ? "ls5" : "boletus";
      m.diameter = 100;
      m.min = pb::Vec3(-50, -50, -50);
      m.size = pb::Vec3(100, 100, 100);
      models[id] = m;
    }
    fs::create_directories(root + "/models");
    pb::write_models_info(root + "/models/models_info.json", models);
    pb::Intrinsics K;
    K.width = 64;
    K.height = 48;
    K.fx = K.fy = 60;
    K.cx = 32;
    K.cy = 24;
    pb::write_camera_json(root + "/camera.json", K, 1.0);
    for (int sid : {1, 2}) {  // scene 1: images 0, 1, 2; scene 2: images 0, 1
      pb::SceneInfo s;
      s.scene_id = sid;
      for (int im = 0; im < (sid == 1 ? 3 : 2); ++im) {
        pb::ImageInfo info;
        info.im_id = im;
        info.K = K;
        s.images[im] = info;
      }
      pb::write_scene_json(root + "/test/" + pb::bop_id(sid), s);
    }
  }
  void targets(const std::string& json) const { std::ofstream(root + "/targets.json") << json; }
  // An experiment on this dataset; `extra` is more YAML of its scene entry.
  std::string experiment(const std::string& extra, const std::string& object = "ls5") const {
    const std::string path = root + "/exp.yaml";
    std::ofstream(path) << "object: " << object << "\nscenes:\n  - name: s\n    dataset: " << root << "\n" << extra
                        << "descriptors: [cvfh, esf]\nrefinements: [none]\n";
    return path;
  }
};

std::set<std::pair<int, int>> images_of(const std::vector<pb::Trial>& trials) {
  std::set<std::pair<int, int>> out;
  for (const auto& t : trials) out.insert({t.scene_id, t.im_id});
  return out;
}

// The InputError `f` throws (a failure when it throws none).
template <typename F>
pb::InputError error_of(F&& f) {
  try {
    f();
  } catch (const pb::InputError& e) {
    return e;
  }
  ADD_FAILURE() << "no InputError";
  return pb::InputError("", "", "");
}

const char* kTargets =
    R"([{"im_id": 0, "inst_count": 1, "obj_id": 1, "scene_id": 1},
        {"im_id": 2, "inst_count": 2, "obj_id": 1, "scene_id": 1},
        {"im_id": 1, "inst_count": 1, "obj_id": 2, "scene_id": 2},
        {"im_id": 0, "inst_count": 1, "obj_id": 1, "scene_id": 2}])";

TEST(TestTargets, ReadsTheBopLayout) {
  Dataset ds;
  ds.targets(kTargets);
  const auto t = pb::read_test_targets(ds.root + "/targets.json");
  ASSERT_EQ(t.size(), 4u);
  EXPECT_EQ(t[1].scene_id, 1);
  EXPECT_EQ(t[1].im_id, 2);
  EXPECT_EQ(t[1].obj_id, 1);
  EXPECT_EQ(t[1].inst_count, 2);
  EXPECT_EQ(t[2].obj_id, 2);
}

// BOP 2019's rule: per image and object, the instances visible at least 10%;
// an object with none is no target; an image without gt_info gives none.
// Written, the list reads back as it was.
TEST(TestTargets, FromTheGroundTruthByVisibilityAndBack) {
  pb::SceneInfo scene;
  scene.scene_id = 3;
  const auto add = [](pb::ImageInfo& im, int obj, double visib) {
    im.gt.push_back({obj, pb::Pose{}});
    pb::GtInfo gi;
    gi.visib_fract = visib;
    im.gt_info.push_back(gi);
  };
  pb::ImageInfo& a = scene.images[0];
  add(a, 5, 0.9);
  add(a, 2, 0.1);    // at the threshold: counted
  add(a, 5, 0.4);
  add(a, 7, 0.09);   // under it: no target
  pb::ImageInfo& b = scene.images[4];
  b.im_id = 4;
  b.gt.push_back({2, pb::Pose{}});  // no gt_info: unknown visibility, no target
  const auto t = pb::scene_test_targets(scene);
  ASSERT_EQ(t.size(), 2u);
  EXPECT_EQ(std::make_tuple(t[0].scene_id, t[0].im_id, t[0].obj_id, t[0].inst_count), std::make_tuple(3, 0, 2, 1));
  EXPECT_EQ(std::make_tuple(t[1].scene_id, t[1].im_id, t[1].obj_id, t[1].inst_count), std::make_tuple(3, 0, 5, 2));
  EXPECT_EQ(pb::scene_test_targets(scene, 0.5).size(), 1u);  // only object 5's first instance

  Dataset ds;
  pb::write_test_targets(ds.root + "/written.json", t);
  const auto back = pb::read_test_targets(ds.root + "/written.json");
  ASSERT_EQ(back.size(), t.size());
  for (size_t i = 0; i < t.size(); ++i)
    EXPECT_EQ(std::make_tuple(back[i].scene_id, back[i].im_id, back[i].obj_id, back[i].inst_count),
              std::make_tuple(t[i].scene_id, t[i].im_id, t[i].obj_id, t[i].inst_count));
  pb::write_test_targets(ds.root + "/empty.json", {});
  EXPECT_TRUE(pb::read_test_targets(ds.root + "/empty.json").empty());
}

TEST(TestTargets, BadEntriesAreInputErrorsNamingTheEntry) {
  Dataset ds;
  const std::string file = ds.root + "/targets.json";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {R"({"im_id": 0})", ""},
      {R"([{"im_id": 0, "inst_count": 1, "obj_id": 1}])", "[0].scene_id"},
      {R"([{"im_id": 0, "inst_count": 1, "obj_id": 1, "scene_id": 1}, 7])", "[1]"},
      {R"([{"im_id": -1, "inst_count": 1, "obj_id": 1, "scene_id": 1}])", "[0].im_id"},
      {R"([{"im_id": 0, "inst_count": 0, "obj_id": 1, "scene_id": 1}])", "[0].inst_count"},
      {R"([{"im_id": 0.5, "inst_count": 1, "obj_id": 1, "scene_id": 1}])", "[0].im_id"},
      {R"([{"im_id": 0, "inst_count": 1, "obj_id": "1", "scene_id": 1}])", "[0].obj_id"},
      {R"([{"im_id": 0, "inst_count": 1, "obj_id": 1, "scene_id": 1e30}])", "[0].scene_id"},
      {R"([{"im_id": 0, "inst_count": 1, "obj_id": 1, "scene_id": 1})", ""},  // truncated
  };
  for (const auto& [text, field] : cases) {
    SCOPED_TRACE(text);
    ds.targets(text);
    const pb::InputError e = error_of([&] { pb::read_test_targets(file); });
    EXPECT_EQ(e.file(), file);
    EXPECT_EQ(e.field(), field);
  }
}

TEST(TestTargets, AnExperimentRunsExactlyTheListedImagesOfItsObject) {
  Dataset ds;
  ds.targets(kTargets);
  const auto all = pb::expand_trials(pb::load_experiment(ds.experiment("")));
  EXPECT_EQ(all.size(), 2u * 5);  // 5 images x 2 descriptors
  const auto cfg = pb::load_experiment(ds.experiment("    targets: targets.json\n"));
  const auto trials = pb::expand_trials(cfg);
  EXPECT_EQ(trials.size(), 2u * 3);
  EXPECT_EQ(images_of(trials), (std::set<std::pair<int, int>>{{1, 0}, {1, 2}, {2, 0}}));
  // scene_ids still selects among them.
  const auto one = pb::expand_trials(pb::load_experiment(ds.experiment("    targets: targets.json\n    scene_ids: [2]\n")));
  EXPECT_EQ(images_of(one), (std::set<std::pair<int, int>>{{2, 0}}));
  // The other object's targets: its one image.
  const auto other = pb::expand_trials(pb::load_experiment(ds.experiment("    targets: targets.json\n", "boletus")));
  EXPECT_EQ(images_of(other), (std::set<std::pair<int, int>>{{2, 1}}));
}

TEST(TestTargets, TheHashChangesOnlyWhenTargetsAreGiven) {
  Dataset ds;
  ds.targets(kTargets);
  const auto plain = pb::load_experiment(ds.experiment(""));
  EXPECT_FALSE(plain.canonical["scenes"][0].contains("targets"));
  const auto with = pb::load_experiment(ds.experiment("    targets: targets.json\n"));
  EXPECT_EQ(with.canonical["scenes"][0]["targets"], "targets.json");
  EXPECT_NE(plain.hash, with.hash);
}

TEST(TestTargets, TargetsOutsideTheDatasetOrNoneForTheObjectAreInputErrors) {
  Dataset ds;
  const std::string file = ds.root + "/targets.json";
  const auto expand = [&] { pb::expand_trials(pb::load_experiment(ds.experiment("    targets: targets.json\n"))); };
  ds.targets(R"([{"im_id": 9, "inst_count": 1, "obj_id": 1, "scene_id": 1}])");
  pb::InputError e = error_of(expand);
  EXPECT_EQ(e.file(), file);
  EXPECT_EQ(e.field(), "[0].im_id");
  ds.targets(R"([{"im_id": 0, "inst_count": 1, "obj_id": 2, "scene_id": 1},
                 {"im_id": 0, "inst_count": 1, "obj_id": 1, "scene_id": 5}])");
  e = error_of(expand);
  EXPECT_EQ(e.field(), "[1].scene_id");
  ds.targets(R"([{"im_id": 0, "inst_count": 1, "obj_id": 2, "scene_id": 1}])");
  e = error_of(expand);
  EXPECT_EQ(e.field(), "obj_id");
  EXPECT_NE(std::string(e.what()).find("ls5"), std::string::npos) << e.what();
  fs::remove(file);
  e = error_of(expand);
  EXPECT_EQ(e.file(), file);
}

// `object: all`: one trial per target (image and object) and method, the
// object and its inst_count in the trial, verify.max_instances set to it, the
// object in the key; every scene needs a dataset with targets; an object
// missing from models_info.json is an InputError naming the entry.
TEST(TestTargets, ObjectAllRunsEveryTargetWithItsInstanceCount) {
  Dataset ds;
  ds.targets(kTargets);
  const auto trials = pb::expand_trials(pb::load_experiment(ds.experiment("    targets: targets.json\n", "all")));
  ASSERT_EQ(trials.size(), 8u);  // 4 targets x 2 descriptors
  std::set<std::tuple<int, int, int, int>> got;
  for (const auto& t : trials) {
    got.insert({t.scene_id, t.im_id, t.obj_id, t.inst_count});
    EXPECT_EQ(t.settings.verify.max_instances, t.inst_count) << t.key;
    EXPECT_NE(t.key.find("/obj=" + std::to_string(t.obj_id)), std::string::npos) << t.key;
    const pb::TrialRecord r = pb::trial_record(t);  // what the worker gets
    EXPECT_EQ(r.obj_id.value_or(0), t.obj_id);
    EXPECT_EQ(r.inst_count.value_or(0), t.inst_count);
  }
  EXPECT_EQ(got, (std::set<std::tuple<int, int, int, int>>{{1, 0, 1, 1}, {1, 2, 1, 2}, {2, 1, 2, 1}, {2, 0, 1, 1}}));
  // Keys stay unique and seeds differ per object.
  std::set<std::string> keys;
  for (const auto& t : trials) keys.insert(t.key);
  EXPECT_EQ(keys.size(), trials.size());

  // Without targets: exit-2 error naming the scene entry.
  const pb::InputError no_targets = error_of([&] { pb::load_experiment(ds.experiment("", "all")); });
  EXPECT_EQ(no_targets.field(), "scenes[0]") << no_targets.what();
  // An object the dataset has no model of.
  ds.targets(R"([{"im_id": 0, "inst_count": 1, "obj_id": 7, "scene_id": 1}])");
  const pb::InputError e = error_of([&] { pb::expand_trials(pb::load_experiment(ds.experiment("    targets: targets.json\n", "all"))); });
  EXPECT_EQ(e.field(), "[0].obj_id");
}

}  // namespace
