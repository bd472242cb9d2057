// BOP dataset writing and reading: identical poses, intrinsics, gt_info and
// models_info (with symmetries) after a round trip; the exact JSON layout
// BOP readers expect; clear InputErrors for bad datasets.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "core/error.h"
#include "core/random.h"
#include "core/rotation.h"
#include "io/bop.h"
#include "io/mesh_io.h"
#include "io/png.h"
#include "temp_dir.h"

namespace fs = std::filesystem;
using namespace pb;

namespace {

using pbtest::TempDir;

std::string slurp(const std::string& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

Mat4 rz180() {
  Mat4 T = Mat4::Identity();
  T(0, 0) = -1;
  T(1, 1) = -1;
  return T;
}

std::map<int, ModelInfo> test_models() {
  std::map<int, ModelInfo> m;
  ModelInfo a;
  a.obj_id = 1;
  a.name = "milk_carton";
  a.diameter = 252.72317170035426;
  a.min = Vec3(-35, -35, -120);
  a.size = Vec3(70, 70, 240);
  Mat4 s = rz180();
  s(0, 3) = 0.1;  // a translation part, mm
  a.symmetries_discrete = {s, rz180()};
  m[1] = a;
  ModelInfo b;
  b.obj_id = 3;
  b.diameter = 1.0 / 3.0;
  b.min = Vec3(-1e-3, 2.5, -7);
  b.size = Vec3(2e-3, 1, 14);
  ContinuousSymmetry c;
  c.axis = Vec3(0, 0, 1);
  c.offset = Vec3(0.5, -0.25, 0);
  b.symmetries_continuous = {c};
  m[3] = b;
  return m;
}

Mesh tetra() {
  Mesh m;
  m.vertices = {{0, 0, 0}, {10, 0, 0}, {0, 10, 0}, {0, 0, 10}};
  m.faces = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  return m;
}

// A small dataset: camera.json, models, test/000007 with 3 images.
SceneInfo write_dataset(const std::string& root, double depth_scale) {
  fs::create_directories(root + "/models");
  write_models_info(root + "/models/models_info.json", test_models());
  write_ply(root + "/models/obj_000001.ply", tetra());
  write_ply(root + "/models/obj_000003.ply", tetra());
  Intrinsics K;
  K.width = 64;
  K.height = 48;
  K.fx = 572.4114;
  K.fy = 573.57043;
  K.cx = 325.2611 / 10;
  K.cy = 242.04899 / 10;
  write_camera_json(root + "/camera.json", K, depth_scale);
  SceneInfo s;
  s.scene_id = 7;
  Rng rng(42);
  for (int im = 0; im < 3; ++im) {
    ImageInfo info;
    info.im_id = im * 5;  // non-contiguous ids
    info.K = K;
    info.K.fx += im * 0.1;
    info.depth_scale = depth_scale;
    for (int g = 0; g < im + 1; ++g) {
      GtObject o;
      o.obj_id = g % 2 ? 3 : 1;
      o.T_cam_model.R = random_rotation(rng);
      o.T_cam_model.t = Vec3(rng.uniform(-300, 300), rng.uniform(-300, 300), rng.uniform(500, 1500));
      info.gt.push_back(o);
      GtInfo gi;
      gi.bbox_obj = {{rng.uniform_int(0, 50), 3, 10, 12}};
      gi.bbox_visib = {{-1, -1, 0, 0}};
      gi.px_count_all = 120 + g;
      gi.px_count_valid = 110;
      gi.px_count_visib = 100;
      gi.visib_fract = 100.0 / 120.0;
      info.gt_info.push_back(gi);
    }
    s.images[info.im_id] = info;
  }
  const std::string dir = root + "/test/" + bop_id(7);
  write_scene_json(dir, s);
  fs::create_directories(dir + "/depth");
  for (const auto& [id, im] : s.images) {
    DepthImage d(K.width, K.height);
    for (size_t i = 0; i < d.z.size(); ++i) d.z[i] = static_cast<float>(((i * 37 + id) % 5000) * depth_scale);
    write_depth_png(bop_depth_path(dir, id), d, depth_scale);
  }
  return s;
}

template <typename F>
void expect_error(F&& f, const std::string& file, const std::string& field_part) {
  try {
    f();
    ADD_FAILURE() << "no InputError for " << file;
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(file), std::string::npos) << msg;
    EXPECT_NE(e.field().find(field_part), std::string::npos) << msg;
  }
}

}  // namespace

TEST(Bop, IdsAreSixDigits) {
  EXPECT_EQ(bop_id(0), "000000");
  EXPECT_EQ(bop_id(42), "000042");
  EXPECT_EQ(bop_depth_path("/d/test/000001", 5), "/d/test/000001/depth/000005.png");
}

TEST(Bop, WriteReadRoundTripIsExact) {
  TempDir tmp;
  const std::string root = tmp / "ds";
  const SceneInfo written = write_dataset(root, 0.1);
  const BopDataset ds(root);
  EXPECT_EQ(ds.splits(), std::vector<std::string>{"test"});
  EXPECT_EQ(ds.scene_ids("test"), std::vector<int>{7});
  ASSERT_TRUE(ds.camera().has_value());
  EXPECT_EQ(ds.camera()->width, 64);
  EXPECT_EQ(ds.camera_depth_scale(), 0.1);
  const SceneInfo read = ds.load_scene("test", 7);
  EXPECT_EQ(read.scene_id, 7);
  ASSERT_EQ(read.images.size(), written.images.size());
  for (const auto& [id, w] : written.images) {
    ASSERT_TRUE(read.images.count(id)) << id;
    const ImageInfo& r = read.images.at(id);
    EXPECT_EQ(r.im_id, id);
    // Bit for bit: JSON numbers are written with round-trip precision.
    EXPECT_EQ(r.K.fx, w.K.fx);
    EXPECT_EQ(r.K.fy, w.K.fy);
    EXPECT_EQ(r.K.cx, w.K.cx);
    EXPECT_EQ(r.K.cy, w.K.cy);
    EXPECT_EQ(r.K.width, 64);   // from camera.json
    EXPECT_EQ(r.K.height, 48);
    EXPECT_EQ(r.depth_scale, 0.1);
    ASSERT_EQ(r.gt.size(), w.gt.size());
    for (size_t g = 0; g < w.gt.size(); ++g) {
      EXPECT_EQ(r.gt[g].obj_id, w.gt[g].obj_id);
      EXPECT_TRUE(r.gt[g].T_cam_model.R == w.gt[g].T_cam_model.R) << r.gt[g].T_cam_model.R;
      EXPECT_TRUE(r.gt[g].T_cam_model.t == w.gt[g].T_cam_model.t) << r.gt[g].T_cam_model.t.transpose();
    }
    ASSERT_EQ(r.gt_info.size(), w.gt_info.size());
    for (size_t g = 0; g < w.gt_info.size(); ++g) {
      EXPECT_EQ(r.gt_info[g].bbox_obj, w.gt_info[g].bbox_obj);
      EXPECT_EQ(r.gt_info[g].bbox_visib, w.gt_info[g].bbox_visib);
      EXPECT_EQ(r.gt_info[g].px_count_all, w.gt_info[g].px_count_all);
      EXPECT_EQ(r.gt_info[g].px_count_valid, w.gt_info[g].px_count_valid);
      EXPECT_EQ(r.gt_info[g].px_count_visib, w.gt_info[g].px_count_visib);
      EXPECT_EQ(r.gt_info[g].visib_fract, w.gt_info[g].visib_fract);
    }
    const DepthImage d = ds.load_depth("test", 7, r);
    ASSERT_EQ(d.width, 64);
    for (size_t i = 0; i < d.z.size(); i += 97)
      EXPECT_EQ(d.z[i], static_cast<float>(((i * 37 + id) % 5000) * 0.1)) << i;
  }
  const Mesh m = ds.load_model(3);
  EXPECT_EQ(m.faces.size(), 4u);
  EXPECT_EQ(ds.model_path(3), root + "/models/obj_000003.ply");
}

TEST(Bop, WidthAndHeightFromDepthWithoutCameraJson) {
  TempDir tmp;
  const std::string root = tmp / "ds";
  write_dataset(root, 1.0);
  fs::remove(root + "/camera.json");
  const BopDataset ds(root);
  EXPECT_FALSE(ds.camera().has_value());
  const SceneInfo s = ds.load_scene("test", 7);
  EXPECT_EQ(s.images.at(5).K.width, 64);
  EXPECT_EQ(s.images.at(5).K.height, 48);
}

TEST(Bop, JsonLayoutIsBop) {
  TempDir tmp;
  const std::string root = tmp / "ds";
  const SceneInfo s = write_dataset(root, 0.1);
  const std::string dir = root + "/test/000007";
  using nlohmann::json;
  const json cam = json::parse(slurp(dir + "/scene_camera.json"));
  const ImageInfo& im5 = s.images.at(5);
  ASSERT_TRUE(cam.contains("5"));
  const std::vector<double> K = cam["5"]["cam_K"];
  EXPECT_EQ(K, (std::vector<double>{im5.K.fx, 0, im5.K.cx, 0, im5.K.fy, im5.K.cy, 0, 0, 1}));
  EXPECT_EQ(cam["5"]["depth_scale"].get<double>(), 0.1);
  const json gt = json::parse(slurp(dir + "/scene_gt.json"));
  const std::vector<double> R = gt["5"][1]["cam_R_m2c"];
  const Mat3& Rw = im5.gt[1].T_cam_model.R;
  EXPECT_EQ(R, (std::vector<double>{Rw(0, 0), Rw(0, 1), Rw(0, 2), Rw(1, 0), Rw(1, 1), Rw(1, 2), Rw(2, 0),
                                    Rw(2, 1), Rw(2, 2)}));  // row-major
  EXPECT_EQ(gt["5"][1]["obj_id"].get<int>(), 3);
  EXPECT_EQ(gt["5"][1]["cam_t_m2c"].size(), 3u);
  const json info = json::parse(slurp(dir + "/scene_gt_info.json"));
  for (const char* k : {"bbox_obj", "bbox_visib", "px_count_all", "px_count_valid", "px_count_visib", "visib_fract"})
    EXPECT_TRUE(info["0"][0].contains(k)) << k;
  const json camera = json::parse(slurp(root + "/camera.json"));
  for (const char* k : {"cx", "cy", "depth_scale", "fx", "fy", "height", "width"})
    EXPECT_TRUE(camera.contains(k)) << k;
  const json mi = json::parse(slurp(root + "/models/models_info.json"));
  EXPECT_EQ(mi["1"]["symmetries_discrete"][0].size(), 16u);  // flattened row-major
  EXPECT_EQ(mi["1"]["symmetries_discrete"][0][3].get<double>(), 0.1);  // translation x at index 3
  EXPECT_EQ(mi["3"]["symmetries_continuous"][0]["offset"][1].get<double>(), -0.25);
  for (const char* k : {"diameter", "min_x", "min_y", "min_z", "size_x", "size_y", "size_z"})
    EXPECT_TRUE(mi["3"].contains(k)) << k;
  EXPECT_FALSE(fs::exists(dir + "/scene_gt.json.tmp"));
}

TEST(Bop, ModelsInfoRoundTripWithSymmetries) {
  TempDir tmp;
  const std::string p = tmp / "models_info.json";
  const auto models = test_models();
  write_models_info(p, models);
  const auto r = read_models_info(p);
  ASSERT_EQ(r.size(), models.size());
  for (const auto& [id, m] : models) {
    const ModelInfo& q = r.at(id);
    EXPECT_EQ(q.obj_id, id);
    EXPECT_EQ(q.name, m.name);
    EXPECT_EQ(q.diameter, m.diameter);
    EXPECT_TRUE(q.min == m.min);
    EXPECT_TRUE(q.size == m.size);
    ASSERT_EQ(q.symmetries_discrete.size(), m.symmetries_discrete.size());
    for (size_t i = 0; i < m.symmetries_discrete.size(); ++i)
      EXPECT_TRUE(q.symmetries_discrete[i] == m.symmetries_discrete[i]) << q.symmetries_discrete[i];
    ASSERT_EQ(q.symmetries_continuous.size(), m.symmetries_continuous.size());
    for (size_t i = 0; i < m.symmetries_continuous.size(); ++i) {
      EXPECT_TRUE(q.symmetries_continuous[i].axis == m.symmetries_continuous[i].axis);
      EXPECT_TRUE(q.symmetries_continuous[i].offset == m.symmetries_continuous[i].offset);
    }
  }
}

TEST(Bop, ResolveObject) {
  TempDir tmp;
  const std::string root = tmp / "ds";
  write_dataset(root, 1.0);
  const BopDataset ds(root);
  EXPECT_EQ(ds.resolve_object("3"), 3);
  EXPECT_EQ(ds.resolve_object("obj_000003"), 3);
  EXPECT_EQ(ds.resolve_object("milk_carton"), 1);
  expect_error([&] { ds.resolve_object("2"); }, root + "/models/models_info.json", "object");
  expect_error([&] { ds.resolve_object("liberty"); }, root + "/models/models_info.json", "object");
  expect_error([&] { ds.model_info(9); }, root + "/models/models_info.json", "9");
}

TEST(Bop, NotABopDatasetNamesThePath) {
  TempDir tmp;
  const std::string empty = tmp / "empty";
  fs::create_directories(empty);
  expect_error([&] { BopDataset ds(empty); }, empty, "dataset");
  expect_error([&] { BopDataset ds(tmp / "nowhere"); }, tmp / "nowhere", "dataset");
  // models but no split
  const std::string only_models = tmp / "models_only";
  fs::create_directories(only_models + "/models");
  write_models_info(only_models + "/models/models_info.json", test_models());
  expect_error([&] { BopDataset ds(only_models); }, only_models, "dataset");
  // a split but no models
  const std::string root = tmp / "ds";
  write_dataset(root, 1.0);
  fs::remove(root + "/models/models_info.json");
  expect_error([&] { BopDataset ds(root); }, root, "dataset");
}

TEST(Bop, MalformedJsonAndMissingKeysNameFileAndKey) {
  TempDir tmp;
  const std::string root = tmp / "ds";
  write_dataset(root, 1.0);
  const std::string dir = root + "/test/000007";
  const std::string gt = dir + "/scene_gt.json";
  const std::string good_gt = slurp(gt);

  // Truncated JSON.
  std::ofstream(gt, std::ios::trunc) << good_gt.substr(0, good_gt.size() / 2);
  try {
    read_scene_json(dir);
    ADD_FAILURE() << "truncated JSON accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), gt);
    EXPECT_NE(std::string(e.what()).find("malformed JSON"), std::string::npos) << e.what();
  }

  // Missing key.
  nlohmann::json j = nlohmann::json::parse(good_gt);
  j["5"][1].erase("cam_t_m2c");
  std::ofstream(gt, std::ios::trunc) << j.dump();
  expect_error([&] { read_scene_json(dir); }, gt, "cam_t_m2c");
  try {
    read_scene_json(dir);
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "5[1].cam_t_m2c");
  }

  // Wrong length of a matrix.
  j = nlohmann::json::parse(good_gt);
  j["0"][0]["cam_R_m2c"].erase(0);
  std::ofstream(gt, std::ios::trunc) << j.dump();
  expect_error([&] { read_scene_json(dir); }, gt, "cam_R_m2c");

  // Non-integer image id.
  j = nlohmann::json::parse(good_gt);
  j["x"] = nlohmann::json::array();
  std::ofstream(gt, std::ios::trunc) << j.dump();
  expect_error([&] { read_scene_json(dir); }, gt, "x");
  std::ofstream(gt, std::ios::trunc) << good_gt;

  // gt_info not parallel to gt.
  const std::string info = dir + "/scene_gt_info.json";
  nlohmann::json ji = nlohmann::json::parse(slurp(info));
  ji["10"].erase(0);
  std::ofstream(info, std::ios::trunc) << ji.dump();
  expect_error([&] { read_scene_json(dir); }, info, "10");

  // models_info without a size.
  const std::string mi = root + "/models/models_info.json";
  nlohmann::json jm = nlohmann::json::parse(slurp(mi));
  jm["3"].erase("size_y");
  std::ofstream(mi, std::ios::trunc) << jm.dump();
  expect_error([&] { BopDataset ds(root); }, mi, "3.size_y");

  // camera.json with a missing fx.
  const std::string cam = tmp / "camera.json";
  std::ofstream(cam) << R"({"cx": 1, "cy": 2, "fy": 3, "width": 4, "height": 5})";
  expect_error([&] { read_camera_json(cam); }, cam, "fx");
}

TEST(Bop, DepthSizeMismatchIsAnInputError) {
  TempDir tmp;
  const std::string root = tmp / "ds";
  write_dataset(root, 1.0);
  const std::string p = root + "/test/000007/depth/000005.png";
  write_depth_png(p, DepthImage(10, 10), 1.0);
  const BopDataset ds(root);
  const SceneInfo s = ds.load_scene("test", 7);
  expect_error([&] { ds.load_depth("test", 7, s.images.at(5)); }, p, "depth");
}

// ------------------------------------------------ validation where data enters

namespace {

// Rewrites one JSON file of the test dataset through `edit`.
template <typename F>
void edit_json(const std::string& path, F&& edit) {
  nlohmann::json j = nlohmann::json::parse(slurp(path));
  edit(j);
  std::ofstream(path, std::ios::trunc) << j.dump();
}

}  // namespace

TEST(BopValidation, CameraJsonIntrinsicsAndDepthScale) {
  TempDir tmp;
  const std::string cam = tmp / "camera.json";
  const auto with = [&](const std::string& fields) {
    std::ofstream(cam, std::ios::trunc) << "{" + fields + "}";
  };
  const std::string size = R"("width": 640, "height": 480, )";
  with(size + R"("fx": 0, "fy": 500, "cx": 320, "cy": 240)");
  expect_error([&] { read_camera_json(cam); }, cam, "fx");
  with(size + R"("fx": 500, "fy": -1, "cx": 320, "cy": 240)");
  expect_error([&] { read_camera_json(cam); }, cam, "fy");
  with(size + R"("fx": 0.9, "fy": 1.2, "cx": 0.5, "cy": 0.5)");  // normalized by the image size
  expect_error([&] { read_camera_json(cam); }, cam, "fx");
  with(size + R"("fx": 500, "fy": 500, "cx": 320, "cy": 4800)");
  expect_error([&] { read_camera_json(cam); }, cam, "cy");
  with(size + R"("fx": 500, "fy": 500, "cx": 320, "cy": null)");
  expect_error([&] { read_camera_json(cam); }, cam, "cy");
  // Found by fuzz/fuzz_bop_camera.cpp: a number too large for a double made
  // the JSON library throw out_of_range, which escaped as an internal error.
  with(size + R"("fx": 955.4e50067, "fy": 500, "cx": 320, "cy": 240)");
  expect_error([&] { read_camera_json(cam); }, cam, "");
  double scale = 0;
  with(size + R"("fx": 500, "fy": 500, "cx": 320, "cy": 240, "depth_scale": 0)");
  expect_error([&] { read_camera_json(cam, &scale); }, cam, "depth_scale");
  with(size + R"("fx": 500, "fy": 500, "cx": 320, "cy": 240, "depth_scale": 0.1)");
  EXPECT_NO_THROW(read_camera_json(cam, &scale));
  EXPECT_EQ(scale, 0.1);
}

TEST(BopValidation, SceneCameraMatrixIsCheckedPerImage) {
  TempDir tmp;
  const std::string root = tmp / "ds";
  write_dataset(root, 1.0);
  const std::string dir = root + "/test/000007";
  const std::string cam = dir + "/scene_camera.json";
  const std::string good = slurp(cam);
  // fx = 0: the defect that gave exit 0 and "no hypothesis".
  edit_json(cam, [](auto& j) { j["5"]["cam_K"][0] = 0; });
  expect_error([&] { read_scene_json(dir); }, cam, "5.cam_K.fx");
  std::ofstream(cam, std::ios::trunc) << good;
  edit_json(cam, [](auto& j) { j["10"]["cam_K"][1] = 0.5; });  // skew
  expect_error([&] { read_scene_json(dir); }, cam, "10.cam_K");
  std::ofstream(cam, std::ios::trunc) << good;
  edit_json(cam, [](auto& j) { j["0"]["cam_K"][8] = 0; });  // not [.. 0 0 1]
  expect_error([&] { read_scene_json(dir); }, cam, "0.cam_K");
  std::ofstream(cam, std::ios::trunc) << good;
  edit_json(cam, [](auto& j) { j["0"]["depth_scale"] = -1; });
  expect_error([&] { read_scene_json(dir); }, cam, "0.depth_scale");
  // The principal point against the image size (64 x 48), known to the dataset.
  std::ofstream(cam, std::ios::trunc) << good;
  edit_json(cam, [](auto& j) { j["5"]["cam_K"][2] = 1000.0; });
  EXPECT_NO_THROW(read_scene_json(dir));
  const BopDataset ds(root);
  expect_error([&] { ds.load_scene("test", 7); }, cam, "5.cam_K.cx");
}

TEST(BopValidation, PosesMustBeRotations) {
  TempDir tmp;
  const std::string root = tmp / "ds";
  const SceneInfo written = write_dataset(root, 1.0);
  const std::string dir = root + "/test/000007";
  const std::string gt = dir + "/scene_gt.json";
  const std::string good = slurp(gt);
  // Scaled by 1.1, a reflection, a shear: each named by file and entry.
  edit_json(gt, [](auto& j) {
    for (auto& v : j["10"][2]["cam_R_m2c"]) v = v.template get<double>() * 1.1;
  });
  expect_error([&] { read_scene_json(dir); }, gt, "10[2].cam_R_m2c");
  std::ofstream(gt, std::ios::trunc) << good;
  edit_json(gt, [](auto& j) {
    for (int c = 0; c < 3; ++c) j["5"][0]["cam_R_m2c"][c] = -j["5"][0]["cam_R_m2c"][c].template get<double>();
  });
  expect_error([&] { read_scene_json(dir); }, gt, "5[0].cam_R_m2c");
  std::ofstream(gt, std::ios::trunc) << good;
  edit_json(gt, [](auto& j) { j["0"][0]["cam_R_m2c"][1] = j["0"][0]["cam_R_m2c"][1].template get<double>() + 0.1; });
  expect_error([&] { read_scene_json(dir); }, gt, "0[0].cam_R_m2c");
  // LM-O's ground truth is off a rotation by up to 0.0137: accepted, as written.
  std::ofstream(gt, std::ios::trunc) << good;
  edit_json(gt, [](auto& j) { j["0"][0]["cam_R_m2c"][1] = j["0"][0]["cam_R_m2c"][1].template get<double>() + 0.0137; });
  EXPECT_NO_THROW(read_scene_json(dir));
  // Rounding in the 8th digit (as in BOP's own files) is accepted.
  std::ofstream(gt, std::ios::trunc) << good;
  edit_json(gt, [](auto& j) {
    for (auto& v : j["0"][0]["cam_R_m2c"]) v = std::round(v.template get<double>() * 1e8) / 1e8;
  });
  EXPECT_NO_THROW(read_scene_json(dir));
}

TEST(BopValidation, SceneGtInfoFieldsAreOptional) {
  TempDir tmp;
  const std::string root = tmp / "ds";
  write_dataset(root, 1.0);
  const std::string dir = root + "/test/000007";
  const std::string info = dir + "/scene_gt_info.json";
  // No bbox_obj anywhere (many converted datasets): read, boxes "not given".
  edit_json(info, [](auto& j) {
    for (auto& [id, list] : j.items())
      for (auto& e : list) e.erase("bbox_obj");
  });
  SceneInfo s = read_scene_json(dir);
  EXPECT_EQ(s.images.at(5).gt_info.at(1).bbox_obj, (std::array<int, 4>{{-1, -1, 0, 0}}));
  EXPECT_NEAR(s.images.at(5).gt_info.at(1).visib_fract, 100.0 / 120.0, 1e-12);
  // visib_fract missing: from the pixel counts; those missing too: unknown.
  edit_json(info, [](auto& j) {
    j["5"][1].erase("visib_fract");
    j["10"][0] = nlohmann::json::object();
  });
  s = read_scene_json(dir);
  EXPECT_NEAR(s.images.at(5).gt_info.at(1).visib_fract, 100.0 / 121.0, 1e-12);
  EXPECT_TRUE(std::isnan(s.images.at(10).gt_info.at(0).visib_fract));
  EXPECT_EQ(s.images.at(10).gt_info.at(0).px_count_all, -1);
  // A present field of the wrong type is still an error.
  edit_json(info, [](auto& j) { j["0"][0]["bbox_visib"] = "wide"; });
  expect_error([&] { read_scene_json(dir); }, info, "0[0].bbox_visib");
  // No scene_gt_info.json at all: the scene reads, without gt_info.
  fs::remove(info);
  EXPECT_TRUE(read_scene_json(dir).images.at(5).gt_info.empty());
}

TEST(BopValidation, SymmetryTransformsMustBeRigid) {
  TempDir tmp;
  const std::string root = tmp / "ds";
  write_dataset(root, 1.0);
  const std::string mi = root + "/models/models_info.json";
  const std::string good = slurp(mi);
  edit_json(mi, [](auto& j) { j["1"]["symmetries_discrete"][1][0] = -2.0; });
  expect_error([&] { read_models_info(mi); }, mi, "1.symmetries_discrete[1]");
  std::ofstream(mi, std::ios::trunc) << good;
  edit_json(mi, [](auto& j) { j["1"]["symmetries_discrete"][0][15] = 2.0; });
  expect_error([&] { read_models_info(mi); }, mi, "1.symmetries_discrete[0]");
  std::ofstream(mi, std::ios::trunc) << good;
  edit_json(mi, [](auto& j) { j["3"]["diameter"] = 0; });
  expect_error([&] { read_models_info(mi); }, mi, "3.diameter");
  std::ofstream(mi, std::ios::trunc) << good;
  edit_json(mi, [](auto& j) { j["3"]["symmetries_continuous"][0]["axis"] = {0, 0, 0}; });
  expect_error([&] { read_models_info(mi); }, mi, "3.symmetries_continuous[0].axis");
  // Six significant digits, as some datasets write them: accepted.
  std::ofstream(mi, std::ios::trunc) << good;
  edit_json(mi, [](auto& j) {
    const double c = std::cos(0.3), s = std::sin(0.3);
    const double r6[] = {std::round(c * 1e6) / 1e6, std::round(s * 1e6) / 1e6};
    j["1"]["symmetries_discrete"][0] = {r6[0], -r6[1], 0, 0.1, r6[1], r6[0], 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  });
  EXPECT_NO_THROW(read_models_info(mi));
}
