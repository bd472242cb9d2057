#include "runner/trial.h"

#include <cmath>
#include <cstdio>
#include <new>
#include <map>
#include <memory>

#include "core/error.h"
#include "core/random.h"
#include "core/rotation.h"
#include "core/timer.h"
#include "eval/bop_metrics.h"
#include "eval/errors.h"
#include "eval/judge.h"
#include "eval/symmetry.h"
#include "io/bop.h"
#include "recognition/pipeline.h"
#include "render/renderer.h"
#include "scenes/views.h"

namespace pb {

namespace {

// Per worker process caches: datasets and trained models are reused across
// the trials a worker runs.
struct WorkerCache {
  std::map<std::string, std::unique_ptr<BopDataset>> datasets;
  std::map<std::string, std::shared_ptr<const TrainedModel>> models;
  std::map<std::string, std::unique_ptr<Mesh>> meshes;
  std::map<std::string, std::unique_ptr<DepthRenderer>> renderers;  // by intrinsics, for VSD
  std::map<std::string, SceneInfo> scenes;        // each scene's JSON files, read once
  std::map<std::string, double> sensor_floors;     // each scene's sensor floor (on its first image),
                                                   // by scene and scale settings
  std::map<std::string, double> view_elevations;   // views.follow_scene: each scene set's, read once
};
WorkerCache& cache() {
  static WorkerCache c;
  return c;
}

const BopDataset& dataset(const std::string& root) {
  auto& d = cache().datasets[root];
  if (!d) d = std::make_unique<BopDataset>(root);
  return *d;
}

// Random streams of a trial (derive_seed ids).
constexpr uint64_t kNoiseStream = 0x6e6f697365ull;    // "noise"
constexpr uint64_t kPerturbStream = 0x7065727475ull;  // "pertu"

// Added noise (the thesis's sigma sweeps), seeded by the trial.
void add_noise(DepthImage& depth, double sigma, uint64_t seed) {
  if (!(sigma > 0)) return;
  Rng rng(derive_seed(seed, {kNoiseStream}));
  for (float& z : depth.z)
    if (z > 0) z = static_cast<float>(std::max(1.0, z + rng.normal(0.0, sigma)));
}

// The trained model: from the worker's memory, the disk cache or training.
// Training is seeded by the settings' own seed (default 1), not by the
// trial: every trial with the same training settings shares one model.
std::shared_ptr<const TrainedModel> trained(const BopDataset& ds, int obj_id, const Mesh& mesh,
                                            const RecognitionSettings& st, const TrialContext& ctx,
                                            TrialRecord& rec) {
  Timer timer;
  // The views as rendered (views.follow_scene resolved for this scene set):
  // the training key and the cache name the elevations actually used.
  RecognitionSettings use = st;
  if (st.views.follow_scene) {
    auto it = cache().view_elevations.find(ds.root());
    if (it == cache().view_elevations.end())
      it = cache().view_elevations.emplace(ds.root(), scene_set_elevation_deg(ds.root())).first;
    use.views = views_at_elevation(st.views, it->second);
  }
  const std::string train_key = ds.root() + "#" + std::to_string(obj_id) + "#" + settings_to_json(use);
  auto& model = cache().models[train_key];
  bool from_cache = model != nullptr;
  if (!model) {
    TrainOptions opt;
    opt.cache_dir = ctx.cache_dir;
    const std::string name = ds.model_info(obj_id).name.empty() ? bop_id(obj_id) : ds.model_info(obj_id).name;
    model = train_model(training_views(mesh, use.views, name), use, opt, &from_cache);
  }
  rec.train_s = timer.seconds();
  rec.train_from_cache = from_cache;
  return model;
}

// Registration alone starts from the ground truth perturbed by a seeded
// random rotation of perturb_deg and translation of perturb_mm.
Pose perturbed(const Pose& gt, const TrialContext& ctx, uint64_t seed) {
  Rng rng(derive_seed(seed, {kPerturbStream}));
  Vec3 axis(rng.normal(), rng.normal(), rng.normal());
  Vec3 dir(rng.normal(), rng.normal(), rng.normal());
  Pose init = gt;
  init.R = axis_angle(axis, ctx.perturb_deg * M_PI / 180.0) * init.R;
  init.t += dir.normalized() * ctx.perturb_mm;
  return init;
}

void record_result(const RecognitionResult& res, TrialRecord& rec) {
  rec.status = res.status;
  if (!res.message.empty()) rec.message = res.message;
  rec.times = StageTimesRecord::from(res.times);
  rec.hypotheses = static_cast<int>(res.hypotheses.size());
  if (res.status == "ok") {
    rec.estimate = PoseRecord::from(res.T_cam_model);
    rec.score = res.score;
    rec.inliers = res.inliers;
  }
}

// The thesis's thresholds of the trial's scenario.
ThesisThresholds thresholds_for(const std::string& scenario, const TrialContext& ctx) {
  return {scenario == "warehouse" ? ctx.thresholds.warehouse_translation_mm : ctx.thresholds.table_translation_mm,
          ctx.thresholds.rotation_1mpq};
}

// The thesis's errors (symmetry-aware), the extra judgements and the BOP
// errors (MSSD, MSPD, VSD with bop19 settings) of an estimate.
// `clean`: the image's depth as stored, without the trial's added noise.
void evaluate(const Pose& est, const GtObject& gt, const BopDataset& ds, const ImageInfo& im, int obj_id,
              const Mesh& mesh, const DepthImage& clean, const TrialContext& ctx, TrialRecord& rec) {
  const ThesisThresholds thr = thresholds_for(rec.scenario, ctx);
  const auto syms = symmetry_transformations(ds.model_info(obj_id));
  const ThesisJudgement judged = thesis_judge(est, gt.T_cam_model, syms, thr);
  const ThesisErrors& e = judged.errors;
  rec.errors = ThesisErrorsRecord{e.translation_mm, e.rotation, e.rotation_deg, e.symmetry,
                                  e.translation_mm_plain, e.rotation_plain};
  rec.correct = judged.correct;
  for (const Judgement& j : ctx.judgements) {
    const auto js = symmetry_transformations(j.symmetries_discrete, j.symmetries_continuous);
    const ThesisJudgement other = thesis_judge(est, gt.T_cam_model, js, thr);
    rec.judgements[j.name] = JudgementRecord{other.correct, other.errors.translation_mm, other.errors.rotation};
  }

  const std::string rkey = std::to_string(im.K.width) + "x" + std::to_string(im.K.height) + ":" +
                           nlohmann::json({im.K.fx, im.K.fy, im.K.cx, im.K.cy}).dump();
  auto& renderer = cache().renderers[rkey];
  if (!renderer) renderer = std::make_unique<DepthRenderer>(im.K);
  BopModel bm;
  bm.mesh = &mesh;
  bm.symmetries = syms;
  bm.diameter = ds.model_info(obj_id).diameter;
  const BopPoseErrors be = bop_pose_errors(est, gt.T_cam_model, bm, im.K, {}, &clean, renderer.get());
  rec.bop = BopErrorsRecord{be.mssd_mm, be.mspd_px, be.vsd, bm.diameter, im.K.width};
}

// The object's ground-truth instances in the image: their poses (the
// judge's candidates) and their indices in im.gt.
struct Instances {
  std::vector<Pose> poses;
  std::vector<size_t> index;
};
Instances instances_of(const ImageInfo& im, int obj_id) {
  Instances out;
  for (size_t g = 0; g < im.gt.size(); ++g)
    if (im.gt[g].obj_id == obj_id) {
      out.poses.push_back(im.gt[g].T_cam_model);
      out.index.push_back(g);
    }
  return out;
}

// The rank of the first hypothesis correct against some instance (the
// thesis's judgement with the model's symmetries), -1 if none.
int first_correct_rank(const std::vector<Hypothesis>& ranked, const Instances& gts, const std::vector<Pose>& syms,
                       const ThesisThresholds& thr) {
  for (size_t i = 0; i < ranked.size(); ++i)
    if (judge(ranked[i].T_cam_model, gts.poses, syms, thr).judged.correct) return static_cast<int>(i);
  return -1;
}

// Every instance of a multi-instance trial (inst_count), judged in rank
// order against the object's GT instances, each GT taken by at most one.
void record_instances(const RecognitionResult& res, const Instances& gts, const std::vector<Pose>& syms,
                      const ThesisThresholds& thr, TrialRecord& rec) {
  rec.instances.emplace();
  std::vector<Pose> estimates;
  for (const Hypothesis& h : res.instances) estimates.push_back(h.T_cam_model);
  const std::vector<InstanceJudgement> judged = judge_in_order(estimates, gts.poses, syms, thr);
  for (size_t i = 0; i < res.instances.size(); ++i) {
    const Hypothesis& h = res.instances[i];
    InstanceRecord inst;
    inst.estimate = PoseRecord::from(h.T_cam_model);
    inst.score = h.verification;
    inst.inliers = h.inliers;
    if (!gts.poses.empty()) inst.correct = judged[i].judged.correct;
    rec.instances->push_back(inst);
  }
}

void run(TrialRecord& rec, const TrialContext& ctx) {
  const BopDataset& ds = dataset(rec.dataset);
  const int obj_id = rec.obj_id ? *rec.obj_id : ds.resolve_object(ctx.object);
  rec.obj_id = obj_id;
  // A scene set does not change while it is run: its scenes' JSON files are
  // read once per worker.
  const std::string scene_key = ds.root() + "#" + rec.split + "#" + std::to_string(rec.scene_id);
  auto scene_it = cache().scenes.find(scene_key);
  if (scene_it == cache().scenes.end())
    scene_it = cache().scenes.emplace(scene_key, ds.load_scene(rec.split, rec.scene_id)).first;
  const SceneInfo& scene = scene_it->second;
  const ImageInfo& im = scene.images.at(rec.im_id);
  const DepthImage depth_clean = ds.load_depth(rec.split, rec.scene_id, im);
  DepthImage depth = depth_clean;
  add_noise(depth, rec.added_noise_mm, rec.seed);

  // The trial's settings (the changes from the defaults the runner sent),
  // lengths in mm for the object and the scene (resolve_for_scene).
  const RecognitionSettings configured =
      parse_recognition_settings(YamlNode::load_string(rec.settings.dump(), "trial " + rec.key));
  double floor = 0;
  if (needs_sensor_floor(configured)) {  // measured once per scene and scale settings
    const ScaleSettings& sc = configured.scale;
    const std::string key = scene_key + "#" + nlohmann::json({sc.sensor_floor_px, sc.sensor_floor_sigmas,
                                                              sc.working_distance_mm}).dump();
    auto it = cache().sensor_floors.find(key);
    if (it == cache().sensor_floors.end()) {
      const ImageInfo& first = scene.images.begin()->second;
      const DepthImage first_depth = first.im_id == im.im_id ? depth_clean : ds.load_depth(rec.split, rec.scene_id, first);
      it = cache().sensor_floors.emplace(key, sensor_length_floor_mm(sc, first_depth, first.K)).first;
    }
    floor = it->second;
  }
  RecognitionSettings s = resolve_for_scene(configured, ds.model_info(obj_id).diameter, floor);
  RecognitionSettings st = s;  // training keeps the settings' seed
  s.seed = rec.seed;
  rec.settings_resolved = nlohmann::json::parse(settings_to_json(s));

  auto& mesh = cache().meshes[ds.root() + "#" + std::to_string(obj_id)];
  if (!mesh) mesh = std::make_unique<Mesh>(ds.load_model(obj_id));
  // Ground truth: the object's instances; registration starts from the first.
  const Instances gts = instances_of(im, obj_id);
  const GtObject* gt = gts.index.empty() ? nullptr : &im.gt[gts.index.front()];
  const auto model = trained(ds, obj_id, *mesh, st, ctx, rec);

  RecognitionResult res;
  if (ctx.registration_only) {
    if (!gt) throw InputError(ds.root(), "scene_gt", "registration_only needs ground truth");
    const Pose init = perturbed(gt->T_cam_model, ctx, rec.seed);
    rec.init = PoseRecord::from(init);
    res = refine_from(depth, im.K, *model, s, init);
  } else {
    res = recognize(depth, im.K, *model, s);
  }
  record_result(res, rec);
  const ThesisThresholds thr = thresholds_for(rec.scenario, ctx);
  const auto syms = symmetry_transformations(ds.model_info(obj_id));
  if (rec.inst_count) record_instances(res, gts, syms, thr, rec);
  if (!gt) return;  // nothing to judge against: no `correct` (as the records always had it)
  // The estimate is judged against the instance it fits best (eval/judge.h);
  // without an estimate the record names the first instance.
  if (res.status == "ok") gt = &im.gt[gts.index[static_cast<size_t>(judge(res.T_cam_model, gts.poses, syms, thr).gt)]];
  rec.gt = PoseRecord::from(gt->T_cam_model);
  if (!res.hypotheses.empty()) rec.correct_rank = first_correct_rank(res.hypotheses, gts, syms, thr);
  const size_t gi = static_cast<size_t>(gt - &im.gt[0]);
  if (gi < im.gt_info.size() && std::isfinite(im.gt_info[gi].visib_fract))  // NaN: not given
    rec.visib_fract = im.gt_info[gi].visib_fract;
  if (res.status == "ok")
    evaluate(res.T_cam_model, *gt, ds, im, obj_id, *mesh, depth_clean, ctx, rec);
  else
    rec.correct = false;
}

}  // namespace

nlohmann::json context_json(const ExperimentConfig& cfg, const std::string& cache_dir) {
  // The judgements as a `judgements:` section, for the workers' parser.
  nlohmann::json section = nlohmann::json::object();
  for (nlohmann::json e : judgements_json(cfg.judgements)) {
    const std::string name = e.at("name");
    e.erase("name");
    section[name] = e;
  }
  nlohmann::json j = {{"object", cfg.object},
                      {"cache_dir", cache_dir},
                      {"table_translation_mm", cfg.thresholds.table_translation_mm},
                      {"warehouse_translation_mm", cfg.thresholds.warehouse_translation_mm},
                      {"rotation_1mpq", cfg.thresholds.rotation_1mpq},
                      {"registration_only", cfg.registration_only},
                      {"perturb_deg", cfg.perturb_deg},
                      {"perturb_mm", cfg.perturb_mm},
                      {"judgements", section}};
  return j;
}

TrialContext context_from_json(const nlohmann::json& c) {
  TrialContext ctx;
  ctx.object = c.at("object");
  ctx.cache_dir = c.at("cache_dir");
  ctx.thresholds.table_translation_mm = c.at("table_translation_mm");
  ctx.thresholds.warehouse_translation_mm = c.at("warehouse_translation_mm");
  ctx.thresholds.rotation_1mpq = c.at("rotation_1mpq");
  ctx.registration_only = c.at("registration_only");
  ctx.perturb_deg = c.at("perturb_deg");
  ctx.perturb_mm = c.at("perturb_mm");
  // The judgements in their YAML shape (JSON is YAML), read by the same parser.
  ctx.judgements = parse_judgements(YamlNode::load_string(c.at("judgements").dump(), "runner context"));
  return ctx;
}

TrialRecord trial_record(const Trial& t) {
  TrialRecord r;
  r.key = t.key;
  r.scene = t.scene_name;
  r.scenario = t.scenario;
  r.dataset = t.dataset;
  r.split = t.split;
  r.scene_id = t.scene_id;
  r.im_id = t.im_id;
  r.descriptor = t.descriptor;
  r.refinement = t.refinement;
  if (t.obj_id > 0) r.obj_id = t.obj_id;
  if (t.inst_count > 0) r.inst_count = t.inst_count;
  r.params = t.params;
  r.added_noise_mm = t.added_noise_mm;
  r.settings = settings_changes_json(t.settings);
  r.seed = t.seed;
  r.status = "pending";  // the worker sets the outcome
  return r;
}

TrialRecord run_trial(const TrialRecord& trial, const TrialContext& ctx) {
  TrialRecord rec = trial;
  Timer wall;
  try {
    run(rec, ctx);
  } catch (const std::bad_alloc&) {  // over the run's --memory-limit-mb (RLIMIT_AS), or out of memory
    rec = trial;
    rec.status = "out_of_memory";
    rec.message = "an allocation failed: the trial needs more memory than the worker may use";
    rec.correct = false;
  } catch (const InputError& e) {
    rec.status = "error";
    rec.message = e.what();
  } catch (const std::exception& e) {
    rec.status = "error";
    rec.message = std::string("exception: ") + e.what();
  }
  rec.wall_s = wall.seconds();
  return rec;
}

}  // namespace pb
