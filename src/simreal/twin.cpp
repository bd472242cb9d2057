// Twin scenes of a real dataset (twin.h).
#include "simreal/twin.h"

#include <filesystem>
#include <nlohmann/json.hpp>
#include <set>

#include "core/error.h"
#include "core/random.h"
#include "io/bop.h"
#include "io/folder.h"
#include "io/png.h"
#include "simreal/frames.h"

namespace pb {

namespace fs = std::filesystem;

namespace {

// The twin image: the GT objects and the plane rendered and degraded; with
// keep_background, the measured depth where no object is drawn.
DepthImage twin_depth(const GtFrame& f, const SensorProfile& sensor, const TwinSettings& s, RendererPool& pool,
                      ModelMeshes& meshes, SupportPlane& plane) {
  const uint64_t sid = static_cast<uint64_t>(f.scene_id), iid = static_cast<uint64_t>(f.info.im_id);
  const TwinRender r = render_twin(pool, meshes, f, derive_seed(s.seed, {7, sid, iid}), s.plane_inlier_mm);
  plane = r.plane;
  SensorProfile prof = sensor;
  prof.K = f.info.K;
  Rng rng(derive_seed(s.seed, {sid, iid}));
  DepthImage d = r.scene.depth;
  apply_noise(d, r.scene, prof, prof.noise, rng);
  if (s.keep_background)
    for (size_t p = 0; p < d.z.size(); ++p)
      if (r.truth.labels[p] < 0) d.z[p] = f.depth.z[p];
  return d;
}

}  // namespace

TwinSummary write_twin(const std::string& real_root, const SensorProfile& sensor, const TwinSettings& s,
                       const std::string& out_dir) {
  const BopDataset ds(real_root);
  std::vector<GtFrame> frames = list_gt_frames(ds, s.split, s.max_images);
  if (fs::exists(out_dir) && !fs::is_empty(out_dir) && !fs::exists(fs::path(out_dir) / "posebench_twin.json"))
    throw InputError(out_dir, "--out", "exists and is not a twin set written by posebench; remove it or choose another");
  TwinSummary sum;
  write_folder_atomically(out_dir, "cannot write the twin set: ", [&](const fs::path& tmp) {
    fs::copy(fs::path(real_root) / "models", tmp / "models", fs::copy_options::recursive);
    if (fs::exists(fs::path(real_root) / "camera.json")) fs::copy(fs::path(real_root) / "camera.json", tmp / "camera.json");
    RendererPool pool;
    ModelMeshes meshes(ds);
    std::map<int, SceneInfo> scenes;
    nlohmann::ordered_json planes = nlohmann::ordered_json::array();
    std::set<std::pair<int, int>> written;
    for (GtFrame& f : frames) {
      load_gt_depth(ds, s.split, f);
      const int sid = f.scene_id, iid = f.info.im_id;
      SupportPlane plane;
      const DepthImage d = twin_depth(f, sensor, s, pool, meshes, plane);
      const fs::path scene_dir = tmp / s.split / bop_id(sid);
      fs::create_directories(scene_dir / "depth");
      write_depth_png(bop_depth_path(scene_dir.string(), iid), d, f.info.depth_scale);
      f.depth = DepthImage();  // one frame's depth in memory at a time
      SceneInfo& sc = scenes[sid];
      sc.scene_id = sid;
      sc.images[iid] = f.info;
      written.insert({sid, iid});
      ++sum.images;
      sum.planes_found += plane.found;
      nlohmann::ordered_json pj = {{"scene_id", sid}, {"im_id", iid}, {"found", plane.found}};
      if (plane.found)
        pj.update({{"normal", {plane.n.x(), plane.n.y(), plane.n.z()}},
                   {"d_mm", plane.d},
                   {"inliers", plane.inliers},
                   {"candidates", plane.candidates}});
      planes.push_back(pj);
    }
    for (const auto& [sid, sc] : scenes) write_scene_json((tmp / s.split / bop_id(sid)).string(), sc);
    const fs::path targets = fs::path(real_root) / "test_targets_bop19.json";
    if (fs::exists(targets)) {
      std::vector<TestTarget> kept;
      for (const TestTarget& t : read_test_targets(targets.string()))
        if (written.count({t.scene_id, t.im_id})) kept.push_back(t);
      write_test_targets((tmp / "test_targets_bop19.json").string(), kept);
    }
    nlohmann::ordered_json prov;
    prov["real_dataset"] = fs::absolute(real_root).lexically_normal().string();
    prov["split"] = s.split;
    prov["sensor"] = sensor.name;
    prov["noise_model"] = sensor.noise.model;
    prov["keep_background"] = s.keep_background;
    prov["seed"] = s.seed;
    prov["images"] = sum.images;
    prov["planes"] = planes;
    atomic_write_text((tmp / "posebench_twin.json").string(), prov.dump(1) + "\n");
  });
  return sum;
}

}  // namespace pb
