#include "runner/trial.h"

#include <cmath>
#include <map>
#include <memory>
#include <mutex>

#include "core/error.h"
#include "core/random.h"
#include "core/rotation.h"
#include "core/timer.h"
#include "eval/bop_metrics.h"
#include "eval/errors.h"
#include "eval/symmetry.h"
#include "io/bop.h"
#include "recognition/pipeline.h"
#include "render/renderer.h"
#include "scenes/views.h"

namespace pb {

static nlohmann::json pose_json(const Pose& T) {
  nlohmann::json R = nlohmann::json::array();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) R.push_back(T.R(r, c));
  return {{"R", R}, {"t", {T.t.x(), T.t.y(), T.t.z()}}};
}

// Per worker process caches: datasets and trained models are reused across
// the trials a worker runs.
struct WorkerCache {
  std::map<std::string, std::unique_ptr<BopDataset>> datasets;
  std::map<std::string, std::shared_ptr<const TrainedModel>> models;
  std::map<std::string, std::unique_ptr<Mesh>> meshes;
  std::map<std::string, std::unique_ptr<DepthRenderer>> renderers;  // by intrinsics, for VSD
};
static WorkerCache& cache() {
  static WorkerCache c;
  return c;
}

static const BopDataset& dataset(const std::string& root) {
  auto& d = cache().datasets[root];
  if (!d) d = std::make_unique<BopDataset>(root);
  return *d;
}

nlohmann::json run_trial(const nlohmann::json& trial, const TrialContext& ctx) {
  nlohmann::json rec = trial;
  rec.erase("settings_json");
  Timer wall;
  try {
    const BopDataset& ds = dataset(trial.at("dataset").get<std::string>());
    const std::string split = trial.at("split");
    const int scene_id = trial.at("scene_id"), im_id = trial.at("im_id");
    const int obj_id = ds.resolve_object(ctx.object);
    rec["obj_id"] = obj_id;

    const SceneInfo scene = ds.load_scene(split, scene_id);
    const ImageInfo& im = scene.images.at(im_id);
    DepthImage depth = ds.load_depth(split, scene_id, im);

    // Added noise (the thesis's sigma sweeps), seeded by the trial.
    const double noise = trial.value("added_noise_mm", 0.0);
    const uint64_t seed = trial.at("seed").get<uint64_t>();
    if (noise > 0) {
      Rng rng(derive_seed(seed, {0x6e6f697365ull}));
      for (float& z : depth.z)
        if (z > 0) z = static_cast<float>(std::max(1.0, z + rng.normal(0.0, noise)));
    }

    const YamlNode settings_node =
        YamlNode::load_string(trial.at("settings").dump(), "trial " + trial.at("key").get<std::string>());
    RecognitionSettings s = parse_recognition_settings(settings_node);
    // Training is seeded by the settings' own seed (default 1), not by the
    // trial: every trial with the same training settings shares one trained
    // model (in memory and in the disk cache) instead of training its own.
    const uint64_t train_seed = s.seed;
    s.seed = seed;
    rec["settings_resolved"] = nlohmann::json::parse(settings_to_json(s));

    const std::string mesh_key = ds.root() + "#" + std::to_string(obj_id);
    auto& mesh = cache().meshes[mesh_key];
    if (!mesh) mesh = std::make_unique<Mesh>(ds.load_model(obj_id));

    // Ground truth: the first instance of the object in the image.
    const GtObject* gt = nullptr;
    for (const auto& g : im.gt)
      if (g.obj_id == obj_id) {
        gt = &g;
        break;
      }

    Timer train_timer;
    RecognitionSettings st = s;
    st.seed = train_seed;
    const std::string train_key = mesh_key + "#" + settings_to_json(st);
    auto& model = cache().models[train_key];
    bool from_cache = model != nullptr;
    if (!model) {
      TrainOptions opt;
      opt.cache_dir = ctx.cache_dir;
      const std::string name = ds.model_info(obj_id).name.empty() ? bop_id(obj_id) : ds.model_info(obj_id).name;
      model = train_model(training_views(*mesh, st.views, name), st, opt, &from_cache);
    }
    rec["train_s"] = train_timer.seconds();
    rec["train_from_cache"] = from_cache;

    RecognitionResult res;
    if (ctx.registration_only) {
      if (!gt) throw InputError(ds.root(), "scene_gt", "registration_only needs ground truth");
      Rng rng(derive_seed(seed, {0x7065727475ull}));
      Vec3 axis(rng.normal(), rng.normal(), rng.normal());
      Vec3 dir(rng.normal(), rng.normal(), rng.normal());
      Pose init = gt->T_cam_model;
      init.R = axis_angle(axis, ctx.perturb_deg * M_PI / 180.0) * init.R;
      init.t += dir.normalized() * ctx.perturb_mm;
      rec["init"] = pose_json(init);
      res = refine_from(depth, im.K, *model, s, init);
    } else {
      res = recognize(depth, im.K, *model, s);
    }

    rec["status"] = res.status;
    if (!res.message.empty()) rec["message"] = res.message;
    rec["times"] = {{"preprocess", res.times.preprocess}, {"describe", res.times.describe},
                    {"match", res.times.match},           {"group", res.times.group},
                    {"initial_pose", res.times.initial_pose}, {"refine", res.times.refine},
                    {"verify", res.times.verify},         {"total", res.times.total()}};
    rec["hypotheses"] = static_cast<int>(res.hypotheses.size());
    if (res.status == "ok") {
      rec["estimate"] = pose_json(res.T_cam_model);
      rec["score"] = res.score;
      rec["inliers"] = res.inliers;
    }
    if (gt) {
      rec["gt"] = pose_json(gt->T_cam_model);
      size_t gi = &*gt - &im.gt[0];
      if (gi < im.gt_info.size()) rec["visib_fract"] = im.gt_info[gi].visib_fract;
      if (res.status == "ok") {
        const std::string scenario = trial.value("scenario", "table");
        ThesisThresholds thr{scenario == "warehouse" ? ctx.warehouse_translation_mm : ctx.table_translation_mm,
                             ctx.rotation_1mpq};
        const auto syms = symmetry_transformations(ds.model_info(obj_id));
        const ThesisErrors e = thesis_errors(res.T_cam_model, gt->T_cam_model, syms, {thr});
        rec["errors"] = {{"translation_mm", e.translation_mm},
                         {"rotation_1mpq", e.rotation},
                         {"rotation_deg", e.rotation_deg},
                         {"symmetry", e.symmetry},
                         {"translation_mm_plain", e.translation_mm_plain},
                         {"rotation_1mpq_plain", e.rotation_plain}};
        rec["correct"] = thesis_correct(e, thr);

        // The BOP errors (MSSD, MSPD, VSD with bop19 settings) of the estimate.
        const std::string rkey = std::to_string(im.K.width) + "x" + std::to_string(im.K.height) + ":" +
                                 nlohmann::json({im.K.fx, im.K.fy, im.K.cx, im.K.cy}).dump();
        auto& renderer = cache().renderers[rkey];
        if (!renderer) renderer = std::make_unique<DepthRenderer>(im.K);
        BopModel bm;
        bm.mesh = mesh.get();
        bm.symmetries = syms;
        bm.diameter = ds.model_info(obj_id).diameter;
        const DepthImage clean = ds.load_depth(split, scene_id, im);  // without the trial's added noise
        const BopPoseErrors be = bop_pose_errors(res.T_cam_model, gt->T_cam_model, bm, im.K, {}, &clean, renderer.get());
        rec["bop"] = {{"mssd_mm", be.mssd_mm}, {"mspd_px", be.mspd_px}, {"vsd", be.vsd},
                      {"diameter", bm.diameter}, {"image_width", im.K.width}};
      } else {
        rec["correct"] = false;
      }
    }
  } catch (const InputError& e) {
    rec["status"] = "error";
    rec["message"] = e.what();
  } catch (const std::exception& e) {
    rec["status"] = "error";
    rec["message"] = std::string("exception: ") + e.what();
  }
  rec["wall_s"] = wall.seconds();
  return rec;
}

}  // namespace pb
