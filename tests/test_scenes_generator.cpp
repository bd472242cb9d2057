// Scene generator: ground truth consistent with the rendered depth (table and
// warehouse), visib_fract against renders of each object alone, BOP round
// trip, determinism, occlusion range, config errors.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iostream>

#include "core/error.h"
#include "core/yaml.h"
#include "io/bop.h"
#include "render/renderer.h"
#include "scenes/generator.h"
#include "scenes/rest_poses.h"
#include "scenes_test_util.h"

namespace fs = std::filesystem;
using namespace pb;

namespace {

const char* kTable = R"(
scenario: table
scene_id: 3
seed: 7
images: 3
sensor: synthetic
noise: none
target: ls5
target_upright_probability: 0.5
distractors: {pool: [milk_carton, boletus, box_small, cylinder], count: [3, 8]}
occlusion: {visib_fract: [0.4, 0.9], probability: 0.5}
)";

const char* kWarehouse = R"(
scenario: warehouse
scene_id: 2
seed: 11
images: 3
sensor: {name: synthetic, max_range_mm: 12000, depth_scale: 0.2}
noise: none
target: ls5
distractors: {pool: [pallet, box_large, barrel, boletus], count: [0, 2]}
occlusion: {visib_fract: [0.4, 0.9], probability: 0.5}
)";

SceneSettings settings_from(const std::string& yaml, const std::string& name = "test.yaml") {
  SceneSettings s = parse_scene_settings(YamlNode::load_string(yaml, name));
  s.name = "test";
  return s;
}

struct TempDir {
  std::string path = pbtest::temp_dir("");
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

// Renders one object alone on a 3x canvas (so parts outside the image count).
struct Alone {
  int px_all = 0;
  DepthImage depth_in_image;  // the object's depth inside the image, 0 elsewhere
};

Alone render_alone(DepthRenderer& big, const Intrinsics& K, const Mesh& mesh, const Pose& T) {
  Alone a;
  const RenderOutput out = big.render({RenderItem{&mesh, T, 0}});
  a.depth_in_image = DepthImage(K.width, K.height);
  for (int y = 0; y < 3 * K.height; ++y)
    for (int x = 0; x < 3 * K.width; ++x) {
      if (out.labels[static_cast<size_t>(y) * 3 * K.width + x] != 0) continue;
      ++a.px_all;
      const int u = x - K.width, v = y - K.height;
      if (u >= 0 && v >= 0 && u < K.width && v < K.height) a.depth_in_image.at(u, v) = out.depth.at(x, y);
    }
  return a;
}

void check_ground_truth(const std::string& yaml, const char* label) {
  const SceneSettings s = settings_from(yaml);
  TempDir tmp;
  const std::string out = tmp.path + "/set";
  const GenerateSummary sum = generate_dataset(s, out);
  ASSERT_EQ(sum.images, 3);
  ASSERT_TRUE(fs::exists(out + "/posebench_scene.json"));
  ASSERT_TRUE(fs::exists(out + "/depth_preview.png"));
  ASSERT_FALSE(fs::exists(out + ".partial"));

  const BopDataset ds(out);
  ASSERT_EQ(ds.scene_ids("test"), std::vector<int>{s.scene_id});
  const SceneInfo scene = ds.load_scene("test", s.scene_id);
  ASSERT_EQ(scene.images.size(), 3u);

  SceneGenerator gen(s);
  Intrinsics Kbig = s.sensor.K;
  Kbig.width *= 3, Kbig.height *= 3, Kbig.cx += s.sensor.K.width, Kbig.cy += s.sensor.K.height;
  DepthRenderer big(Kbig);
  std::vector<double> all_dist;
  int objects = 0;
  for (int im = 0; im < 3; ++im) {
    const GeneratedImage img = gen.generate(im);
    const ImageInfo& info = scene.images.at(im);
    // BOP round trip: identical poses, intrinsics, gt_info.
    EXPECT_EQ(info.K.fx, img.info.K.fx);
    EXPECT_EQ(info.K.fy, img.info.K.fy);
    EXPECT_EQ(info.K.cx, img.info.K.cx);
    EXPECT_EQ(info.K.cy, img.info.K.cy);
    EXPECT_EQ(info.depth_scale, s.depth_scale);
    ASSERT_EQ(info.gt.size(), img.info.gt.size());
    ASSERT_EQ(info.gt_info.size(), img.info.gt.size());
    ASSERT_GE(info.gt.size(), 1u);
    EXPECT_EQ(info.gt[0].obj_id, gen.model("ls5").obj_id);
    for (size_t k = 0; k < info.gt.size(); ++k) {
      EXPECT_EQ(info.gt[k].obj_id, img.info.gt[k].obj_id);
      EXPECT_TRUE(info.gt[k].T_cam_model.R == img.info.gt[k].T_cam_model.R);
      EXPECT_TRUE(info.gt[k].T_cam_model.t == img.info.gt[k].T_cam_model.t);
      EXPECT_EQ(info.gt_info[k].px_count_visib, img.info.gt_info[k].px_count_visib);
    }
    const DepthImage depth = ds.load_depth("test", s.scene_id, info);
    ASSERT_EQ(depth.width, s.sensor.K.width);

    for (size_t k = 0; k < info.gt.size(); ++k) {
      ++objects;
      const Mesh mesh = ds.load_model(info.gt[k].obj_id);
      const Pose T_model_cam = info.gt[k].T_cam_model.inverse();
      // Depth pixels where the object is visible, mapped into the model.
      pbtest::MeshDistance md(mesh, 20.0);
      std::vector<double> dist;
      for (int v = 0; v < depth.height; ++v)
        for (int u = 0; u < depth.width; ++u) {
          if (img.labels[static_cast<size_t>(v) * depth.width + u] != static_cast<int>(k)) continue;
          const float z = depth.at(u, v);
          if (!(z > 0)) continue;
          dist.push_back(md.distance(T_model_cam * info.K.backproject(u, v, z)));
        }
      const GtInfo& gi = info.gt_info[k];
      EXPECT_EQ(static_cast<int>(dist.size()), gi.px_count_visib) << label << " im " << im << " gt " << k;
      if (!dist.empty()) {
        const double med = pbtest::percentile(dist, 0.5), p99 = pbtest::percentile(dist, 0.99);
        EXPECT_LE(med, 0.5) << label << " im " << im << " gt " << k;
        EXPECT_LE(p99, 2.0) << label << " im " << im << " gt " << k;
        all_dist.insert(all_dist.end(), dist.begin(), dist.end());
      }
      // visib_fract against a render of the object alone.
      const Alone a = render_alone(big, info.K, mesh, info.gt[k].T_cam_model);
      EXPECT_EQ(a.px_all, gi.px_count_all) << label << " im " << im << " gt " << k;
      EXPECT_NEAR(gi.visib_fract, static_cast<double>(gi.px_count_visib) / std::max(1, a.px_all), 1e-12);
      // BOP's own visibility test: the object's depth alone agrees with the
      // scene's (noise-free) depth.
      int visib_bop = 0;
      for (size_t p = 0; p < a.depth_in_image.z.size(); ++p) {
        const float za = a.depth_in_image.z[p];
        if (za > 0 && std::abs(img.depth_clean.z[p] - za) < 0.5f) ++visib_bop;
      }
      EXPECT_LE(std::abs(visib_bop - gi.px_count_visib), std::max(2, gi.px_count_all / 100))
          << label << " im " << im << " gt " << k;
      EXPECT_LE(gi.px_count_visib, gi.px_count_all);
      EXPECT_GE(gi.visib_fract, 0.0);
      EXPECT_LE(gi.visib_fract, 1.0);
    }
    // The target is in view.
    EXPECT_GT(info.gt_info[0].visib_fract, 0.39);
  }
  ASSERT_GT(all_dist.size(), 1000u);
  std::cout << "[ GT       ] " << label << ": " << objects << " objects, " << all_dist.size()
            << " visible pixels, distance to mesh median " << pbtest::percentile(all_dist, 0.5) << " mm, p99 "
            << pbtest::percentile(all_dist, 0.99) << " mm, max " << pbtest::percentile(all_dist, 1.0) << " mm\n";
  EXPECT_LE(pbtest::percentile(all_dist, 0.5), 0.5);
  EXPECT_LE(pbtest::percentile(all_dist, 0.99), 2.0);
}

}  // namespace

TEST(SceneGenerator, TableGroundTruthMatchesDepth) { check_ground_truth(kTable, "table"); }

TEST(SceneGenerator, WarehouseGroundTruthMatchesDepth) { check_ground_truth(kWarehouse, "warehouse"); }

TEST(SceneGenerator, ObjectsRestOnTheTableWithoutOverlap) {
  SceneGenerator gen(settings_from(kTable));
  for (int im = 0; im < 3; ++im) {
    const GeneratedImage img = gen.generate(im);
    std::vector<Eigen::AlignedBox3d> boxes;
    for (size_t k = 0; k < img.info.gt.size(); ++k) {
      const Pose T_world_model = img.T_world_cam * img.info.gt[k].T_cam_model;
      const Mesh& mesh = [&]() -> const Mesh& {
        for (const auto& m : gen.models())
          if (m.obj_id == img.info.gt[k].obj_id) return m.mesh;
        throw std::runtime_error("unknown obj_id");
      }();
      double zmin = 1e300;
      for (const auto& v : mesh.vertices) zmin = std::min(zmin, (T_world_model * v.cast<double>()).z());
      EXPECT_NEAR(zmin, 0.0, 1e-6) << "im " << im << " gt " << k;
    }
    // Camera between 0.6 and 1.5 m, looking down 30 to 70 degrees.
    EXPECT_GE(img.camera_distance_mm, 600);
    EXPECT_LE(img.camera_distance_mm, 1500);
    EXPECT_GE(img.camera_elevation_deg, 30);
    EXPECT_LE(img.camera_elevation_deg, 70);
    // 1 target + 3..8 distractors placed (some may fall outside the image).
    EXPECT_LE(img.info.gt.size(), 9u);
  }
}

// The target (gt[0]) rests with its lowest point on the ground, and the
// depth where it is visible lies on its mesh at the ground-truth pose
// (noise: none).
void expect_target_on_ground_and_depth(const GeneratedImage& img, const SceneModel& target, int im) {
  const Pose T_world_model = img.T_world_cam * img.info.gt[0].T_cam_model;
  double zmin = 1e300;
  for (const auto& v : target.mesh.vertices) zmin = std::min(zmin, (T_world_model * v.cast<double>()).z());
  EXPECT_NEAR(zmin, 0.0, 1e-6) << "im " << im;
  pbtest::MeshDistance md(target.mesh, 20.0);
  const Pose T_model_cam = img.info.gt[0].T_cam_model.inverse();
  std::vector<double> dist;
  for (int v = 0; v < img.depth.height; ++v)
    for (int u = 0; u < img.depth.width; ++u) {
      const float z = img.depth.at(u, v);
      if (img.labels[static_cast<size_t>(v) * img.depth.width + u] != 0 || !(z > 0)) continue;
      dist.push_back(md.distance(T_model_cam * img.info.K.backproject(u, v, z)));
    }
  ASSERT_GT(dist.size(), 100u) << "im " << im;
  EXPECT_LE(pbtest::percentile(dist, 0.99), 2.0) << "im " << im;
}

// target_free_probability 1: the target lies on its lowest point in
// orientations no rest pose gives (a rest pose fixes the tilt: row 2 of
// Rz(yaw) R_rest is row 2 of R_rest), and the ground truth still matches the
// depth.
TEST(SceneGenerator, FreeTargetOrientationRestsOnItsLowestPoint) {
  const std::string free_cfg = std::string(kTable) + "target_free_probability: 1\n";
  SceneGenerator gen(settings_from(free_cfg));
  const SceneModel& target = gen.model("ls5");
  const RestPoses rest = compute_rest_poses(target.mesh);
  ASSERT_FALSE(rest.poses.empty());
  for (int im = 0; im < 4; ++im) {
    const GeneratedImage img = gen.generate(im);
    const Pose T_world_model = img.T_world_cam * img.info.gt[0].T_cam_model;
    double nearest = 1e300;
    for (const auto& p : rest.poses) nearest = std::min(nearest, (T_world_model.R.row(2) - p.R_rest.row(2)).norm());
    EXPECT_GT(nearest, 1e-3) << "im " << im << ": the target's tilt is a rest pose's";
    expect_target_on_ground_and_depth(img, target, im);
  }
  EXPECT_EQ(settings_from(kTable).target_free_probability, 0.0);  // rest poses only unless asked
}

// target_tilt_deg 20, upright only: the target's up axis leans from the
// vertical by at most 20 degrees (more than 2 in some image), its lowest
// point on the ground, and the ground truth matches the depth.
TEST(SceneGenerator, TiltedTargetLeansAtMostTheTiltOnItsLowestPoint) {
  std::string cfg = kTable;
  cfg.replace(cfg.find("target_upright_probability: 0.5"), 31, "target_upright_probability: 1");
  cfg += "target_tilt_deg: 20\n";
  SceneGenerator gen(settings_from(cfg));
  const SceneModel& target = gen.model("ls5");
  const RestPoses rest = compute_rest_poses(target.mesh);
  ASSERT_GE(rest.upright, 0);
  const Vec3 up_model = rest.poses[static_cast<size_t>(rest.upright)].R_rest.transpose() * Vec3::UnitZ();
  double most = 0;
  for (int im = 0; im < 6; ++im) {
    const GeneratedImage img = gen.generate(im);
    const Pose T_world_model = img.T_world_cam * img.info.gt[0].T_cam_model;
    const double lean = std::acos(std::min(1.0, (T_world_model.R * up_model).z())) * 180.0 / M_PI;
    EXPECT_LE(lean, 20.0 + 1e-6) << "im " << im;
    most = std::max(most, lean);
    expect_target_on_ground_and_depth(img, target, im);
  }
  EXPECT_GT(most, 2.0) << "no image leaned";
  EXPECT_EQ(settings_from(kTable).target_tilt_deg, 0.0);
}

TEST(SceneGenerator, SameSeedSameImageAnyOrder) {
  const SceneSettings s = settings_from(kTable);
  SceneGenerator a(s), b(s);
  const GeneratedImage a0 = a.generate(0);
  const GeneratedImage a1 = a.generate(1);
  const GeneratedImage b1 = b.generate(1);  // without image 0 first
  EXPECT_EQ(a1.depth.z, b1.depth.z);
  EXPECT_EQ(a1.labels, b1.labels);
  EXPECT_NE(a0.depth.z, a1.depth.z);
  SceneSettings s2 = s;
  s2.seed = 8;
  SceneGenerator c(s2);
  EXPECT_NE(c.generate(1).depth.z, a1.depth.z);
}

TEST(SceneGenerator, OcclusionLandsInRange) {
  SceneSettings s = settings_from(kTable);
  s.occlusion.enabled = true;
  s.occlusion.probability = 1.0;
  s.occlusion.visib_fract = {0.4, 0.9};
  SceneGenerator gen(s);
  for (int im = 0; im < 4; ++im) {
    const GeneratedImage img = gen.generate(im);
    EXPECT_TRUE(img.occluded);
    EXPECT_GT(img.occluder_height_mm, 0);
    EXPECT_GE(img.info.gt_info[0].visib_fract, 0.4) << im;
    EXPECT_LE(img.info.gt_info[0].visib_fract, 0.9) << im;
  }
}

TEST(SceneGenerator, NoOccluderKeepsTargetVisible) {
  SceneSettings s = settings_from(kTable);
  s.occlusion.enabled = false;
  s.min_target_visib = 0.9;
  SceneGenerator gen(s);
  for (int im = 0; im < 3; ++im) {
    const GeneratedImage img = gen.generate(im);
    EXPECT_FALSE(img.occluded);
    EXPECT_GE(img.info.gt_info[0].visib_fract, 0.9);
  }
}

TEST(SceneGenerator, WarehouseObjectsAreLarge) {
  SceneGenerator gen(settings_from(kWarehouse));
  for (const auto& m : gen.models()) {
    const double extent = m.mesh.bounds().sizes().maxCoeff();
    EXPECT_GE(extent, 1000 - 1e-3) << m.name;
    EXPECT_LE(extent, 1500 + 1e-3) << m.name;
  }
  const GeneratedImage img = gen.generate(0);
  EXPECT_GE(img.camera_distance_mm, 2000);
  EXPECT_LE(img.camera_distance_mm, 5000);
  EXPECT_GE(img.info.gt.size(), 1u);
  EXPECT_LE(img.info.gt.size(), 3u);
}

// distractors.spread_max_radii caps the disc the other objects stand in:
// each one's origin lies within that many target footprint radii of the
// target's on the ground (the footprint radius is at most the target mesh's
// radius about its origin). On the table the disc is otherwise as wide as
// the view, several target radii: without the cap (the same seed) some
// object stands farther.
TEST(SceneGenerator, SpreadCapKeepsOtherObjectsNearTheTarget) {
  const std::string from = "distractors: {pool: [milk_carton, boletus, box_small, cylinder], count: [3, 8]}";
  const auto farthest = [&](const std::string& distractors) {
    std::string yaml = kTable;
    yaml.replace(yaml.find(from), from.size(), distractors);
    SceneGenerator gen(settings_from(yaml));
    double radius = 0;  // of the target mesh about its origin
    for (const auto& v : gen.model("ls5").mesh.vertices) radius = std::max(radius, v.cast<double>().norm());
    double most = 0;  // the farthest other object, in target radii
    int others = 0;
    for (int im = 0; im < 3; ++im) {
      const GeneratedImage img = gen.generate(im);
      const Vec3 t0 = (img.T_world_cam * img.info.gt[0].T_cam_model).t;
      for (size_t k = 1; k < img.info.gt.size(); ++k) {
        const Vec3 tk = (img.T_world_cam * img.info.gt[k].T_cam_model).t;
        most = std::max(most, (tk - t0).head<2>().norm() / radius);
        ++others;
      }
    }
    EXPECT_GE(others, 4) << distractors;
    return most;
  };
  const std::string pool = "distractors: {pool: [boletus, box_small, cylinder], count: [2, 3], spread_min_radii: 2.5";
  const double capped = farthest(pool + ", spread_max_radii: 3}");
  const double free = farthest(pool + "}");
  std::cout << "[ spread   ] farthest other object: " << capped << " target radii capped at 3, " << free
            << " without the cap\n";
  EXPECT_LE(capped, 3 + 1e-9);
  EXPECT_GT(free, 3);
}

TEST(SceneGenerator, ImpossibleOcclusionIsAnInputError) {
  SceneSettings s = settings_from(kTable);
  s.occlusion.enabled = true;
  s.occlusion.probability = 1.0;
  s.occlusion.visib_fract = {0.0, 0.001};
  s.distractors.min_count = s.distractors.max_count = 0;
  s.max_attempts = 3;
  SceneGenerator gen(s);
  try {
    gen.generate(0);
    // A fully hidden target can happen; then nothing to check.
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "occlusion");
    EXPECT_NE(std::string(e.what()).find("test.yaml"), std::string::npos);
  }
}

TEST(SceneGenerator, OutputDirIsReplacedOnlyIfItIsASceneSet) {
  TempDir tmp;
  SceneSettings s = settings_from(kTable);
  s.images = 1;
  const std::string out = tmp.path + "/other";
  fs::create_directories(out);
  std::ofstream(out + "/precious.txt") << "keep";
  EXPECT_THROW(generate_dataset(s, out), InputError);
  EXPECT_TRUE(fs::exists(out + "/precious.txt"));
  const std::string out2 = tmp.path + "/set";
  generate_dataset(s, out2);
  generate_dataset(s, out2);  // replaces a previous scene set
  EXPECT_TRUE(fs::exists(out2 + "/posebench_scene.json"));
  EXPECT_FALSE(fs::exists(out2 + ".partial"));
  EXPECT_FALSE(fs::exists(out2 + ".old"));
}

TEST(SceneGenerator, MissingModelLeavesNothing) {
  TempDir tmp;
  SceneSettings s = settings_from(kTable);
  s.target = "no_such_model";
  const std::string out = tmp.path + "/set";
  try {
    generate_dataset(s, out);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "target");
    EXPECT_NE(std::string(e.what()).find("no_such_model"), std::string::npos);
  }
  EXPECT_FALSE(fs::exists(out));
  EXPECT_FALSE(fs::exists(out + ".partial"));
}

// warehouse.wall: false leaves the floor as the one plane (the thesis's
// warehouse). Seen from 5 degrees above, the wall fills the top rows; the
// floor alone leaves them empty (sky), and the targets are the same.
TEST(SceneGenerator, WarehouseWithoutWallHasOnlyTheFloor) {
  const std::string low = std::string(kWarehouse) + "camera: {elevation_deg: [5, 5]}\n";
  SceneGenerator with(settings_from(low));
  SceneGenerator without(settings_from(low + "warehouse: {wall: false}\n"));
  const GeneratedImage a = with.generate(0), b = without.generate(0);
  const auto top_valid = [](const DepthImage& d) {
    int n = 0;
    for (int u = 0; u < d.width; ++u) n += d.at(u, 0) > 0;
    return n;
  };
  EXPECT_GT(top_valid(a.depth), a.depth.width / 2);
  EXPECT_EQ(top_valid(b.depth), 0);
  ASSERT_EQ(a.info.gt.size(), b.info.gt.size());
  EXPECT_EQ(a.info.gt[0].obj_id, b.info.gt[0].obj_id);
}

// A room around the table (table.floor_drop_mm, table.wall_distance_mm): the
// points of the noise-free depth, in the scene's world frame (z up, the
// table top at z = 0), reach down to the floor beyond the table's edges but
// not below it, and back to the wall behind the table but not beyond it;
// without the room nothing lies below the table top.
TEST(SceneGenerator, TableRoomHasAFloorBelowAndAWallBehind) {
  const auto world_points = [](const std::string& table, std::vector<Vec3>& out, Eigen::Vector2d& g) {
    std::string yaml = kTable;
    const std::string occluded = "occlusion: {visib_fract: [0.4, 0.9], probability: 0.5}\n";
    yaml.replace(yaml.find(occluded), occluded.size(), "occlusion: none\n");
    yaml += "camera: {distance_mm: 2000, elevation_deg: 30}\n" + table;
    SceneGenerator gen(settings_from(yaml));
    const GeneratedImage img = gen.generate(0);
    const OrganizedCloud c = OrganizedCloud::from_depth(img.depth_clean, img.info.K);
    for (const Vec3f& p : c.points)
      if (p.allFinite()) out.push_back(img.T_world_cam * p.cast<double>());
    g = img.T_world_cam.t.head<2>().normalized();  // from the target (the origin) toward the camera
  };
  std::vector<Vec3> room, bare;
  Eigen::Vector2d g, g_bare;
  world_points("table: {size_mm: 1200, floor_drop_mm: 750, wall_distance_mm: 300}\n", room, g);
  world_points("table: {size_mm: 1200}\n", bare, g_bare);
  ASSERT_GT(room.size(), 1000u);
  ASSERT_GT(bare.size(), 1000u);
  double far = 0;  // the table's farthest corner from the origin, away from the camera
  for (const double x : {-600.0, 600.0})
    for (const double y : {-600.0, 600.0}) far = std::max(far, -g.dot(Eigen::Vector2d(x, y)));
  const double wall = far + 300;  // the wall's face, along -g
  int on_floor = 0, on_wall = 0;
  double lowest = 0, deepest = 0;
  for (const Vec3& p : room) {
    lowest = std::min(lowest, p.z());
    deepest = std::max(deepest, -g.dot(p.head<2>()));
    if (std::abs(p.z() + 750) < 5 && (std::abs(p.x()) > 610 || std::abs(p.y()) > 610)) ++on_floor;
    if (std::abs(-g.dot(p.head<2>()) - wall) < 5 && p.z() > 0) ++on_wall;
  }
  std::cout << "[ room     ] " << on_floor << " floor and " << on_wall << " wall pixels of " << room.size()
            << "; lowest z " << lowest << " mm, deepest " << deepest << " mm (wall at " << wall << ")\n";
  EXPECT_GT(on_floor, 100);
  EXPECT_GT(on_wall, 100);
  EXPECT_GT(lowest, -750 - 1);
  EXPECT_LT(deepest, wall + 1);
  double bare_lowest = 0;
  for (const Vec3& p : bare) bare_lowest = std::min(bare_lowest, p.z());
  EXPECT_GT(bare_lowest, -40 - 1);  // the table top's thickness at most
}
