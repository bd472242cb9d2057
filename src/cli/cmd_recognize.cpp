// posebench recognize --dataset DIR --scene S --image I --object NAME_OR_ID
//   [--method cesf] [--refine icp_plane] [--views 12] [--config FILE]
//   [--overlay out.png] [--json] [--cache DIR]
// posebench recognize --cloud SCENE.pcd [--units m] [--intrinsics ...]
//   (--object REGISTRY_NAME | --model MESH) [...]
// One image of any BOP-layout dataset, or one point cloud, through one descriptor x refinement
// combination: prints the pose, inliers, stage times and, where ground truth
// exists, the thesis's errors (symmetry-aware, from eval/errors.h).
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>

#include "cli/command.h"
#include "core/error.h"
#include "core/timer.h"
#include "eval/errors.h"
#include "eval/judge.h"
#include "eval/symmetry.h"
#include "io/bop.h"
#include "io/png.h"
#include "recognition/pipeline.h"
#include "recognition/registry.h"
#include "scenes/views.h"
#include "cli/recognize_input.h"
#include "report/overlay.h"

namespace {

std::string default_cache_dir() {
  if (const char* e = std::getenv("POSEBENCH_CACHE")) return e;
  if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x) return std::string(x) + "/posebench/train";
  if (const char* h = std::getenv("HOME"); h && *h) return std::string(h) + "/.cache/posebench/train";
  return "";
}

nlohmann::ordered_json times_json(const pb::StageTimes& t) {
  nlohmann::ordered_json j;
  pb::StageTimes::each([&](const char* name, double pb::StageTimes::*stage) { j[name] = t.*stage; });
  j["total"] = t.total();
  return j;
}

// "preprocess 0.01, describe 0.02, ..., initial pose 0, ...; total 0.1"
std::string times_text(const pb::StageTimes& t) {
  std::ostringstream o;
  const char* sep = "";
  pb::StageTimes::each([&](std::string name, double pb::StageTimes::*stage) {
    std::replace(name.begin(), name.end(), '_', ' ');
    o << sep << name << " " << t.*stage;
    sep = ", ";
  });
  o << "; total " << t.total();
  return o.str();
}

struct Options {
  pbcli::RecognizeSource src;
  std::string method, refine, config, overlay, cache = default_cache_dir(), scenario = "table";
  int views = 0;
  int instances = -1;  // verify.max_instances (-1: the config's)
  std::optional<uint64_t> seed;  // a record's seed is any 64-bit number
  bool json = false;
  bool explain = false;
};

void add_options(CLI::App& app, Options& o) {
  pbcli::RecognizeSource& s = o.src;
  app.add_option("--dataset", s.dataset_dir, "BOP dataset root (models/, test/ ...)");
  app.add_option("--split", s.split, "split folder (default: test if present, else the first)");
  app.add_option("--scene", s.scene, "scene id (with --dataset)");
  app.add_option("--image", s.image, "image id (with --dataset)");
  app.add_option("--cloud", s.cloud, "instead of a dataset image: a point cloud, .pcd (PCL's format) or .ply, "
                                     "in the camera frame (x right, y down, z forward)");
  app.add_option("--units", s.units, "the cloud's units: m, mm or auto (metres when the median depth is below 20)");
  app.add_option("--intrinsics", s.intrinsics, "the cloud's camera: fx,fy,cx,cy[,width,height] (default: fitted to "
                                               "an organized cloud; a virtual 640x480 camera for an unorganized one)");
  app.add_option("--camera", s.camera, "the cloud's camera as a BOP camera.json");
  app.add_option("--object", s.object, "object id, obj_XXXXXX or name (models_info.json; without --dataset: "
                                       "a name in the model registry, `posebench models`)");
  app.add_option("--model", s.model, "instead of --object: a mesh file (PLY, OBJ, STL, OFF) in mm, or a point "
                                     "cloud of the object seen from one side (.pcd, or .ply without faces; trained "
                                     "as one view, model origin at its bounding-box centre)");
  app.add_option("--model-units", s.model_units, "a cloud model's units: m, mm or auto");
  app.add_option("--method", o.method, "descriptor: fpfh shot cvfh esf cesf ourcvfh ppf (default: config, else fpfh)");
  app.add_option("--refine", o.refine, "refinement: none icp icp_lm icp_plane gicp ndt (default: config, else icp)");
  app.add_option("--views", o.views, "training views (1, 8, 12 or N on a sphere)")->check(CLI::PositiveNumber);
  app.add_option("--config", o.config, "recognition settings YAML (sections descriptor, refinement, views, "
                                       "preprocess, local, global, ppf, refine, verify, seed)");
  app.add_option("--instances", o.instances, "recognize up to N instances of the object (0 = every one that "
                                             "verification accepts; default: the config's verify.max_instances, 1)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--seed", o.seed, "seed of the recognition's random choices (overrides the config's seed; training "
                                   "keeps the config's, as in `posebench run`: a record's seed repeats its trial)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--overlay", o.overlay, "write a PNG: the model at the estimated pose over the colour-mapped depth");
  app.add_option("--cache", o.cache, "training cache folder ('' = no cache; default $POSEBENCH_CACHE or ~/.cache/posebench/train)");
  app.add_option("--scenario", o.scenario, "thresholds for 'correct': table (50 mm) or warehouse (100 mm)");
  app.add_flag("--json", o.json, "print one JSON object");
  app.add_flag("--explain", o.explain, "also every ranked hypothesis (verification, inliers, view, the method's "
               "score, errors against the nearest ground-truth instance) and the ground truth's own pose refined "
               "and verified as one more hypothesis: where it would rank");
}

// Settings from --config, then the flags.
void settings_from(const Options& o, pb::RecognitionSettings& s) {
  if (!o.config.empty()) s = pb::parse_recognition_settings(pb::YamlNode::load_file(o.config), s);
  if (!o.method.empty()) s.descriptor = pb::descriptor_entry(o.method, "", "--method").name;
  if (!o.refine.empty()) s.refinement = pb::refinement_entry(o.refine, "", "--refine").name;
  if (o.views > 0) s.views.views = o.views;
  if (o.instances >= 0) s.verify.max_instances = o.instances;
}

// The thesis's errors of a pose against the object's ground-truth instance
// it fits best (eval/judge.h, the runner's judge); none when the image has no
// instance of the object.
struct NearestGt {
  pb::ThesisErrors err;
  pb::Pose gt_pose;
};
std::optional<NearestGt> nearest_gt(const pb::Pose& T, const pb::ImageInfo& im, int obj_id,
                                    const std::vector<pb::Pose>& syms, const pb::ThesisThresholds& thr) {
  std::vector<pb::Pose> gts;
  for (const auto& g : im.gt)
    if (g.obj_id == obj_id) gts.push_back(g.T_cam_model);
  const pb::InstanceJudgement j = pb::judge(T, gts, syms, thr);
  if (j.gt < 0) return std::nullopt;
  return NearestGt{j.judged.errors, gts[static_cast<size_t>(j.gt)]};
}

// The estimate against the ground-truth instance it is closest to.
struct Evaluation {
  bool has_gt = false, correct = false;
  pb::ThesisErrors err;
  pb::Pose gt_pose;
  int gt_instances = 0;
};

Evaluation evaluate(const pb::RecognitionResult& res, const pb::ImageInfo& im, int obj_id, const pb::ModelInfo& info,
                    const pb::ThesisThresholds& thr) {
  Evaluation ev;
  for (const auto& g : im.gt) ev.gt_instances += g.obj_id == obj_id;
  if (res.status == "ok" && ev.gt_instances > 0) {
    const std::optional<NearestGt> n = nearest_gt(res.T_cam_model, im, obj_id, pb::symmetry_transformations(info), thr);
    ev.has_gt = n.has_value();
    if (n) ev.err = n->err, ev.gt_pose = n->gt_pose;
  } else if (ev.gt_instances > 0) {
    for (const auto& g : im.gt)
      if (g.obj_id == obj_id) {
        ev.gt_pose = g.T_cam_model;
        break;
      }
  }
  ev.correct = ev.has_gt && pb::thesis_correct(ev.err, thr);
  return ev;
}

// --explain: each ranked hypothesis against the nearest GT instance, and
// the ground truth itself refined and verified like a hypothesis.
struct RankedHypothesis {
  pb::Hypothesis h;
  std::optional<pb::ThesisErrors> err;  // none without a GT instance of the object
};
struct Explanation {
  std::vector<RankedHypothesis> ranked;
  std::optional<pb::Hypothesis> gt_refined;  // the GT pose refined and verified
  int gt_rank = 0;                           // where it would rank (0 = first)
};

Explanation explain(const pb::RecognitionResult& res, const pb::ImageInfo& im, int obj_id, const pb::ModelInfo& info,
                    const pb::ThesisThresholds& thr, const pb::RecognitionResult* gt_res) {
  Explanation x;
  const auto syms = pb::symmetry_transformations(info);
  for (const pb::Hypothesis& h : res.hypotheses) {
    const std::optional<NearestGt> n = nearest_gt(h.T_cam_model, im, obj_id, syms, thr);
    x.ranked.push_back({h, n ? std::optional<pb::ThesisErrors>(n->err) : std::nullopt});
  }
  if (gt_res && !gt_res->hypotheses.empty()) {
    x.gt_refined = gt_res->hypotheses.front();
    for (const pb::Hypothesis& h : res.hypotheses) x.gt_rank += h.verification > x.gt_refined->verification;
  }
  return x;
}

// What the command prints, in either form.
struct Outcome {
  const Options& o;
  const pb::RecognitionSettings& s;
  const pb::RecognitionResult& res;
  const Evaluation& ev;
  const pb::ImageInfo& im;
  const pbcli::RecognizeScene& scene;
  int obj_id;
  std::string model_name;
  int train_views;
  double train_s;
  bool from_cache;
  const Explanation* explanation;
};

std::vector<double> pose_R(const pb::Pose& T) {
  std::vector<double> R;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) R.push_back(T.R(r, c));
  return R;
}
std::vector<double> pose_t(const pb::Pose& T) { return {T.t[0], T.t[1], T.t[2]}; }

std::string json_output(const Outcome& x) {
  const bool ok = x.res.status == "ok";
  nlohmann::ordered_json j;
  j["status"] = x.res.status;
  if (!x.res.message.empty()) j["message"] = x.res.message;
  for (const auto& [k, v] : x.scene.source.items()) j[k] = v;
  j["object"] = {{"id", x.obj_id}, {"name", x.model_name}};
  j["method"] = x.s.descriptor;
  j["refinement"] = x.s.refinement;
  if (ok) {
    j["R"] = pose_R(x.res.T_cam_model);
    j["t"] = pose_t(x.res.T_cam_model);
  } else {
    j["R"] = nullptr;
    j["t"] = nullptr;
  }
  j["score"] = x.res.score;
  j["inliers"] = x.res.inliers;
  j["settings_resolved"] = pb::recognition_settings_json(x.s);  // every field in mm, as a run's record has them
  if (x.s.verify.max_instances != 1) {
    nlohmann::ordered_json list = nlohmann::ordered_json::array();
    for (const auto& h : x.res.instances)
      list.push_back({{"R", pose_R(h.T_cam_model)}, {"t", pose_t(h.T_cam_model)}, {"verification", h.verification},
                      {"inliers", h.inliers}});
    j["instances"] = list;
  }
  j["hypotheses"] = x.res.hypotheses.size();
  j["times"] = times_json(x.res.times);
  j["train"] = {{"seconds", x.train_s}, {"from_cache", x.from_cache}, {"views", x.train_views}};
  j["ground_truth_instances"] = x.ev.gt_instances;
  if (x.ev.has_gt)
    j["errors"] = {{"translation_mm", x.ev.err.translation_mm},
                   {"rotation", x.ev.err.rotation},
                   {"rotation_deg", x.ev.err.rotation_deg},
                   {"symmetry_aware", true},
                   {"symmetry", x.ev.err.symmetry},
                   {"translation_mm_plain", x.ev.err.translation_mm_plain},
                   {"rotation_plain", x.ev.err.rotation_plain},
                   {"rotation_deg_plain", x.ev.err.rotation_deg_plain},
                   {"scenario", x.o.scenario},
                   {"correct", x.ev.correct}};
  if (x.explanation) {
    nlohmann::ordered_json list = nlohmann::ordered_json::array();
    for (const RankedHypothesis& r : x.explanation->ranked) {
      nlohmann::ordered_json h = {{"verification", r.h.verification}, {"inliers", r.h.inliers}, {"view", r.h.view},
                                  {"score", r.h.score}, {"R", pose_R(r.h.T_cam_model)}, {"t", pose_t(r.h.T_cam_model)}};
      if (r.err) h["errors"] = {{"translation_mm", r.err->translation_mm}, {"rotation_deg", r.err->rotation_deg}};
      list.push_back(h);
    }
    j["ranked"] = list;
    if (const auto& g = x.explanation->gt_refined)
      j["ground_truth_refined"] = {{"verification", g->verification}, {"inliers", g->inliers},
                                   {"would_rank", x.explanation->gt_rank}, {"R", pose_R(g->T_cam_model)},
                                   {"t", pose_t(g->T_cam_model)}};
  }
  if (!x.o.overlay.empty()) j["overlay"] = x.o.overlay;
  return j.dump() + "\n";
}

std::string text_output(const Outcome& x, const pb::ThesisThresholds& thr) {
  const pb::RecognitionResult& res = x.res;
  std::ostringstream o;
  o << std::setprecision(6);
  o << "object " << x.model_name << " (id " << x.obj_id << ") in " << x.scene.description << ": "
    << x.s.descriptor << " + " << x.s.refinement << "\n";
  o << "training: " << x.train_views << " views, " << x.train_s << " s" << (x.from_cache ? " (from cache)" : "")
    << "\n";
  o << "status: " << res.status;
  if (!res.message.empty()) o << " (" << res.message << ")";
  o << "\n";
  if (res.status == "ok") {
    o << "pose T_cam_model (model to camera, mm):\n";
    for (int r = 0; r < 3; ++r)
      o << "  " << std::setw(10) << res.T_cam_model.R(r, 0) << " " << std::setw(10) << res.T_cam_model.R(r, 1)
        << " " << std::setw(10) << res.T_cam_model.R(r, 2) << " | " << std::setw(10) << res.T_cam_model.t[r]
        << "\n";
    o << "inliers: " << res.inliers << "  score: " << res.score << "  hypotheses: " << res.hypotheses.size()
      << "\n";
    if (x.s.verify.max_instances != 1) {
      o << "instances: " << res.instances.size() << "\n";
      for (size_t i = 0; i < res.instances.size(); ++i)
        o << "  " << i + 1 << ": t = (" << res.instances[i].T_cam_model.t.transpose() << ") mm, verification "
          << res.instances[i].verification << ", inliers " << res.instances[i].inliers << "\n";
    }
  }
  o << "times (s): " << times_text(res.times) << "\n";
  if (x.ev.has_gt)
    o << "errors vs ground truth (symmetry-aware): translation " << x.ev.err.translation_mm << " mm, 1-|p.q| "
      << x.ev.err.rotation << ", angle " << x.ev.err.rotation_deg << " deg -> "
      << (x.ev.correct ? "correct" : "not correct") << " (" << x.o.scenario << " thresholds " << thr.translation_mm
      << " mm, " << thr.rotation << ")\n";
  else if (x.ev.gt_instances == 0 && !x.im.gt.empty())
    o << "ground truth: the object is not annotated in this image\n";
  else if (x.im.gt.empty())
    o << "ground truth: none for this image\n";
  if (x.explanation) {
    o << "ranked hypotheses (verification, inliers, view, method score; errors vs the nearest GT instance):\n";
    for (size_t i = 0; i < x.explanation->ranked.size(); ++i) {
      const RankedHypothesis& r = x.explanation->ranked[i];
      o << "  " << i << ": " << r.h.verification << ", " << r.h.inliers << ", view " << r.h.view << ", " << r.h.score;
      if (r.err) o << "; " << r.err->translation_mm << " mm, " << r.err->rotation_deg << " deg";
      o << "\n";
    }
    if (const auto& g = x.explanation->gt_refined)
      o << "ground truth refined and verified: verification " << g->verification << ", inliers " << g->inliers
        << " (would rank " << x.explanation->gt_rank << ")\n";
  }
  if (!x.o.overlay.empty()) o << "overlay: " << x.o.overlay << "\n";
  return o.str();
}

}  // namespace

static pb::cli::Command recognize_cmd(
    "recognize", "recognize one object in one image of a BOP dataset or in a point cloud", [](int argc, char** argv) {
      CLI::App app{"Recognizes one object in one depth image of a BOP-layout dataset, or in a point cloud (PCD "
                   "or PLY), and prints its pose, inliers, stage times and, where ground truth exists, the errors."};
      Options o;
      add_options(app, o);
      PB_CLI_PARSE(app, argc, argv);

      pb::RecognitionSettings s;
      settings_from(o, s);
      const pb::ThesisThresholds thr = pb::thesis_thresholds(o.scenario);

      const pbcli::RecognizeScene scene = pbcli::load_recognize_scene(o.src);
      const pbcli::RecognizeObject obj = pbcli::load_recognize_object(o.src);
      const pb::DepthImage& depth = scene.depth;
      const pb::ImageInfo& im = scene.im;
      const pb::Mesh& mesh = obj.mesh;
      const int obj_id = obj.obj_id;
      const std::string& model_name = obj.name;
      const pb::ModelInfo& info = obj.info;

      pb::Timer train_timer;
      pb::TrainOptions topt;
      topt.cache_dir = o.cache;
      bool from_cache = false;
      if (s.views.follow_scene) {  // the scene set's camera elevations (InputError without a scene set)
        if (o.src.dataset_dir.empty())
          throw pb::InputError("", "views.follow_scene", "needs --dataset (a scene set made by `posebench generate`)");
        s.views = pb::views_for_scene_set(s.views, o.src.dataset_dir);
      }
      const pb::TrainingViews views = obj.cloud.empty() ? pb::training_views(mesh, s.views, model_name)
                                                        : pb::cloud_training_views(obj.cloud, model_name);
      // Relative lengths in mm as `posebench run` resolves them: the model's
      // diameter (models_info, else the training views' extent), the
      // sensor's floor at the scene's first image.
      if (!views.views.empty())
        s = pb::resolve_for_scene(s, info.diameter > 0 ? info.diameter : pb::training_views_diameter(views),
                                  scene.first_depth, scene.first_K);
      // Training is seeded by the settings' seed, the recognition by --seed
      // (the runner's trial seed), as `posebench run` does.
      const auto model = pb::train_model(views, s, topt, &from_cache);
      if (o.seed) s.seed = *o.seed;
      const double train_s = train_timer.seconds();
      const pb::RecognitionResult res = pb::recognize(depth, im.K, *model, s);
      const Evaluation ev = evaluate(res, im, obj_id, info, thr);
      if (!o.overlay.empty())
        pb::write_overlay(o.overlay, depth, im.K, mesh, res.status == "ok" ? &res.T_cam_model : nullptr,
                      ev.gt_instances > 0 ? &ev.gt_pose : nullptr);
      std::unique_ptr<Explanation> why;
      if (o.explain) {
        pb::RecognitionResult gt_res;
        if (ev.gt_instances > 0) gt_res = pb::refine_from(depth, im.K, *model, s, ev.gt_pose);
        why = std::make_unique<Explanation>(explain(res, im, obj_id, info, thr, ev.gt_instances > 0 ? &gt_res : nullptr));
      }
      const Outcome x{o,        s,         res, ev, im, scene, obj_id, model_name, pb::trained_model_info(*model).views,
                      train_s, from_cache, why.get()};
      std::cout << (o.json ? json_output(x) : text_output(x, thr));
      return 0;
    });
