// The fitted sensor profiles (results/sensors/real/*/profile.yaml) against
// the real frames they were fitted to: twins of other frames (or another
// noise seed) rendered with the profile give the statistics of the real
// frames (fit_loss, sensor_fit.h), well below the loss of the profile the
// fit started from. Needs the real frames: POSEBENCH_REAL_DATA, or
// ../shared/real_data beside the project (scripts/real_data.py builds them);
// skipped, visibly, without them.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>

#include "core/random.h"
#include "core/yaml.h"
#include "render/sensor.h"
#include "simreal/frames.h"
#include "simreal/sensor_fit.h"

using namespace pb;
namespace fs = std::filesystem;

namespace {

std::string real_data_root() {
  if (const char* e = std::getenv("POSEBENCH_REAL_DATA"); e && *e) return e;
  const fs::path shared = fs::path(POSEBENCH_SOURCE_DIR) / ".." / "shared" / "real_data";
  return fs::exists(shared) ? shared.string() : "";
}

SensorProfile profile_file(const std::string& rel) {
  return parse_sensor(YamlNode::load_file(std::string(POSEBENCH_SOURCE_DIR) + "/" + rel));
}

struct Losses {
  FitLoss profile, other;
};

// The real statistics of every stride-th frame, and those of their twins
// with `profile` and with `other` (noise seed 99, not the fit's).
Losses losses(const std::string& dataset, int stride, const SensorProfile& profile, const SensorProfile& other) {
  const BopDataset ds(dataset);
  RendererPool pool;
  ModelMeshes meshes(ds);
  SensorStatsAccumulator real, a, b;
  for (GtFrame& f : list_gt_frames(ds, "test", 0, stride)) {
    load_gt_depth(ds, "test", f);
    const int sid = f.scene_id, iid = f.info.im_id;
    std::vector<int> ids;
    for (const auto& g : f.info.gt) ids.push_back(g.obj_id);
    const TwinRender tr = render_twin(pool, meshes, f, 5);
    const RenderOutput &truth = tr.truth, &scene = tr.scene;
    real.add(f.depth, truth, f.info.K, ids);
    for (auto [prof, acc] : {std::pair<SensorProfile, SensorStatsAccumulator*>{profile, &a}, {other, &b}}) {
      prof.K = f.info.K;
      prof.min_range_mm = std::min(prof.min_range_mm, 200.0);
      DepthImage d = scene.depth;
      Rng rng(derive_seed(99, {static_cast<uint64_t>(sid), static_cast<uint64_t>(iid)}));
      apply_noise(d, scene, prof, prof.noise, rng);
      acc->add(d, truth, f.info.K, ids);
    }
  }
  const SensorStats r = real.finish();
  return {fit_loss(r, a.finish()), fit_loss(r, b.finish())};
}

}  // namespace

TEST(SimrealProfiles, StructuredLightFitMatchesTheRealFrames) {
  const std::string root = real_data_root();
  if (root.empty() || !fs::exists(root + "/ycbv")) GTEST_SKIP() << "no real frames (POSEBENCH_REAL_DATA/ycbv)";
  // Every 7th frame: mostly others than the fit's (every 4th).
  const Losses l = losses(root + "/ycbv", 7, profile_file("results/sensors/real/ycbv/profile.yaml"),
                          profile_file("configs/sensors/astra_no_gt.yaml"));
  std::printf("ycbv: loss with the fit %.3f (noise %.3f, incidence %.3f, edge %.3f, silhouette %.3f); "
              "without %.3f\n",
              l.profile.total(), l.profile.noise, l.profile.incidence, l.profile.edge, l.profile.silhouette,
              l.other.total());
  EXPECT_LT(l.profile.total(), 3.0);
  EXPECT_LT(l.profile.total(), 0.3 * l.other.total());
}

TEST(SimrealProfiles, TimeOfFlightFitMatchesTheRealFrames) {
  const std::string root = real_data_root();
  if (root.empty() || !fs::exists(root + "/graspnet_kinect"))
    GTEST_SKIP() << "no real frames (POSEBENCH_REAL_DATA/graspnet_kinect)";
  const Losses l = losses(root + "/graspnet_kinect", 1,
                          profile_file("results/sensors/real/graspnet_kinect/profile.yaml"),
                          sensor_profile("kinect_one"));
  std::printf("graspnet_kinect: loss with the fit %.3f, with kinect_one %.3f\n", l.profile.total(), l.other.total());
  EXPECT_LT(l.profile.total(), 4.0);
  EXPECT_LT(l.profile.total(), 0.5 * l.other.total());
}
