// Several instances of one object (verify.max_instances, issue 9; BOP's
// inst_count): a rendered scene with two copies of an asymmetric object in
// front of a wall. With max_instances 2 (and 0: every accepted one) PPF +
// ICP returns both, each within 10 mm and 5 degrees of a different copy;
// with 1 it returns one. Also the pieces the multi-instance PPF rests on:
// the voxel grid's normal clustering and the neighbouring feature bins.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/rotation.h"
#include "models/procedural.h"
#include "recognition/pipeline.h"
#include "recognition/ppf/internal.h"
#include "recognition/preprocess/voxel_grid.h"
#include "recognition_train_util.h"
#include "render/renderer.h"
#include "test_recognition_refine_scenes.h"

namespace pb {
namespace {

struct TwoCopies {
  Mesh object = refine_test::asymmetric_object();
  Mesh wall = make_box(3000, 3000, 20);
  Intrinsics K = Intrinsics::from_fov(640, 480, 50, 38);
  Pose a, b;
  DepthImage depth;
  TwoCopies() {
    a.R = axis_angle(Vec3(1, 0.3, 0), 2.2);
    a.t = Vec3(-120, 0, 800);
    b.R = axis_angle(Vec3(0.2, 1, 0.5), 1.1);
    b.t = Vec3(130, 20, 820);
    Pose w;
    w.t = Vec3(0, 0, 1000);
    DepthRenderer r(K);
    depth = r.render({{&object, a, 1}, {&object, b, 2}, {&wall, w, 3}}).depth;
  }
};

bool near(const Pose& est, const Pose& gt) {
  return (est.t - gt.t).norm() < 10 && Eigen::AngleAxisd(est.R.transpose() * gt.R).angle() < 5 * M_PI / 180;
}

class Instances : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scene_ = new TwoCopies;
    settings_.descriptor = "ppf";
    settings_.refinement = "icp";
    model_ = test::train(scene_->object, settings_);
  }
  static void TearDownTestSuite() {
    delete scene_;
    model_.reset();
  }
  RecognitionResult run(int max_instances) const {
    RecognitionSettings s = settings_;
    s.verify.max_instances = max_instances;
    return recognize(scene_->depth, scene_->K, *model_, s);
  }
  static TwoCopies* scene_;
  static RecognitionSettings settings_;
  static std::shared_ptr<const TrainedModel> model_;
};
TwoCopies* Instances::scene_ = nullptr;
RecognitionSettings Instances::settings_;
std::shared_ptr<const TrainedModel> Instances::model_;

TEST_F(Instances, TwoRequestedGivesEachCopyOnce) {
  for (int max_instances : {2, 0}) {
    const RecognitionResult res = run(max_instances);
    ASSERT_EQ(res.status, "ok") << res.message;
    ASSERT_GE(res.instances.size(), 2u) << "max_instances " << max_instances;
    if (max_instances == 2) EXPECT_EQ(res.instances.size(), 2u);
    const bool ab = near(res.instances[0].T_cam_model, scene_->a) && near(res.instances[1].T_cam_model, scene_->b);
    const bool ba = near(res.instances[0].T_cam_model, scene_->b) && near(res.instances[1].T_cam_model, scene_->a);
    EXPECT_TRUE(ab || ba) << "max_instances " << max_instances << ": first at " << res.instances[0].T_cam_model.t.transpose()
                          << ", second at " << res.instances[1].T_cam_model.t.transpose();
    // The first instance is the chosen pose; instances are ranked.
    EXPECT_EQ(res.instances[0].T_cam_model.t, res.T_cam_model.t);
    for (size_t i = 1; i < res.instances.size(); ++i) {
      EXPECT_LE(res.instances[i].verification, res.instances[i - 1].verification);
      for (size_t j = 0; j < i; ++j)
        EXPECT_GT((res.instances[i].T_cam_model.t - res.instances[j].T_cam_model.t).norm(), 1.0)
            << "instances " << j << " and " << i << " are the same";
    }
  }
}

TEST_F(Instances, OneRequestedGivesOne) {
  const RecognitionResult res = run(1);
  ASSERT_EQ(res.status, "ok") << res.message;
  ASSERT_EQ(res.instances.size(), 1u);
  EXPECT_TRUE(near(res.T_cam_model, scene_->a) || near(res.T_cam_model, scene_->b)) << res.T_cam_model.t.transpose();
}

// Two faces of a cube corner in one voxel: one point per face with normal
// clustering (and their normals), one averaged point without.
TEST(VoxelNormalClusters, KeepsBothSidesOfAnEdge) {
  PointSet in;
  for (int i = 0; i < 5; ++i) {
    in.points.emplace_back(1.0f + i, 0.0f, 5.0f);  // top face, normal +z
    in.normals.emplace_back(0.0f, 0.0f, 1.0f);
    in.points.emplace_back(0.0f, 1.0f + i, 4.0f);  // side face, normal -x
    in.normals.emplace_back(-1.0f, 0.0f, 0.0f);
  }
  VoxelGridOptions o;
  o.leaf_mm = 10;
  EXPECT_EQ(voxel_downsample(in, o).size(), 1u);
  o.normal_cluster_deg = 30;
  const PointSet out = voxel_downsample(in, o);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_NEAR(out.normals[0].z(), 1.0f, 1e-6);
  EXPECT_NEAR(out.normals[1].x(), -1.0f, 1e-6);
  EXPECT_NEAR(out.points[0].z(), 5.0f, 1e-6);
  EXPECT_NEAR(out.points[1].x(), 0.0f, 1e-6);
  // A 100 degree cluster angle joins them again.
  o.normal_cluster_deg = 100;
  EXPECT_EQ(voxel_downsample(in, o).size(), 1u);
}

// A feature value within the margin of a bin edge also looks up the bin
// across it; 0 margin: the own bin only.
TEST(PpfNeighbourKeys, NearEdgesAddTheNeighbouringBins) {
  const float step[4] = {1, 1, 1, 10};
  uint64_t keys[16];
  const float mid[4] = {0.5f, 1.5f, 2.5f, 35};
  EXPECT_EQ(ppf::neighbour_keys(mid, step, 0.25f, keys), 1);
  EXPECT_EQ(keys[0], ppf::pack_key(0, 1, 2, 3));
  const float edges[4] = {0.1f, 1.95f, 2.5f, 31};  // low edge, high edge, middle, low edge
  ASSERT_EQ(ppf::neighbour_keys(edges, step, 0.25f, keys), 8);
  EXPECT_EQ(keys[0], ppf::pack_key(0, 1, 2, 3));  // own bin first
  std::vector<uint64_t> got(keys, keys + 8);
  for (int64_t a : {0, -1})
    for (int64_t b : {1, 2})
      for (int64_t d : {3, 2})
        EXPECT_NE(std::find(got.begin(), got.end(), ppf::pack_key(a, b, 2, d)), got.end()) << a << " " << b << " " << d;
  EXPECT_EQ(ppf::neighbour_keys(edges, step, 0.0f, keys), 1);
}

}  // namespace
}  // namespace pb
