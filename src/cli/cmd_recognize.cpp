// posebench recognize --dataset DIR --scene S --image I --object NAME_OR_ID
//   [--method cesf] [--refine icp_plane] [--views 12] [--config FILE]
//   [--overlay out.png] [--json] [--cache DIR]
// One image of any BOP-layout dataset through one descriptor x refinement
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
#include <sstream>

#include "cli/command.h"
#include "core/error.h"
#include "core/timer.h"
#include "eval/errors.h"
#include "eval/symmetry.h"
#include "io/bop.h"
#include "io/png.h"
#include "recognition/pipeline.h"
#include "recognition/registry.h"
#include "scenes/views.h"
#include "render/renderer.h"

namespace {

std::string default_cache_dir() {
  if (const char* e = std::getenv("POSEBENCH_CACHE")) return e;
  if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x) return std::string(x) + "/posebench/train";
  if (const char* h = std::getenv("HOME"); h && *h) return std::string(h) + "/.cache/posebench/train";
  return "";
}

// A perceptual-ish colour map (blue -> cyan -> yellow -> red) for depth.
void colormap(double x, uint8_t* rgb) {
  x = std::clamp(x, 0.0, 1.0);
  static const double stops[5][3] = {{48, 18, 59}, {40, 150, 230}, {60, 220, 120}, {250, 200, 40}, {180, 20, 10}};
  const double f = x * 4.0;
  const int i = std::min(3, static_cast<int>(f));
  const double w = f - i;
  for (int c = 0; c < 3; ++c) rgb[c] = static_cast<uint8_t>(std::lround(stops[i][c] * (1 - w) + stops[i + 1][c] * w));
}

// The scene depth colour-mapped (near = blue, far = red; no depth = black),
// the model rendered at the estimated pose tinted green with a bright
// outline, and the ground truth (if any) outlined in magenta.
void write_overlay(const std::string& path, const pb::DepthImage& depth, const pb::Intrinsics& K,
                   const pb::Mesh& mesh, const pb::Pose* est, const pb::Pose* gt) {
  const int w = depth.width, h = depth.height;
  std::vector<float> valid;
  for (float z : depth.z)
    if (z > 0 && std::isfinite(z)) valid.push_back(z);
  double lo = 0, hi = 1;
  if (!valid.empty()) {
    std::sort(valid.begin(), valid.end());
    lo = valid[valid.size() / 100];
    hi = valid[valid.size() - 1 - valid.size() / 100];
    if (hi <= lo) hi = lo + 1;
  }
  std::vector<uint8_t> rgb(static_cast<size_t>(w) * h * 3, 0);
  for (int i = 0; i < w * h; ++i) {
    const float z = depth.z[i];
    if (z > 0 && std::isfinite(z)) colormap((z - lo) / (hi - lo), &rgb[3 * i]);
  }
  pb::DepthRenderer renderer(K);
  auto mask_of = [&](const pb::Pose& T) {
    pb::RenderItem item;
    item.mesh = &mesh;
    item.T_cam_model = T;
    item.label = 1;
    const pb::RenderOutput out = renderer.render({item});
    std::vector<char> m(static_cast<size_t>(w) * h, 0);
    for (size_t i = 0; i < m.size() && i < out.labels.size(); ++i) m[i] = out.labels[i] == 1;
    return m;
  };
  auto outline = [&](const std::vector<char>& m, int x, int y) {
    if (!m[static_cast<size_t>(y) * w + x]) return false;
    const int dx[4] = {1, -1, 0, 0}, dy[4] = {0, 0, 1, -1};
    for (int k = 0; k < 4; ++k) {
      const int u = x + dx[k], v = y + dy[k];
      if (u < 0 || v < 0 || u >= w || v >= h || !m[static_cast<size_t>(v) * w + u]) return true;
    }
    return false;
  };
  if (est) {
    const auto m = mask_of(*est);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const size_t i = static_cast<size_t>(y) * w + x;
        if (!m[i]) continue;
        uint8_t* p = &rgb[3 * i];
        if (outline(m, x, y)) {
          p[0] = 120, p[1] = 255, p[2] = 120;
        } else {
          p[0] = static_cast<uint8_t>(p[0] * 0.4);
          p[1] = static_cast<uint8_t>(p[1] * 0.4 + 255 * 0.6);
          p[2] = static_cast<uint8_t>(p[2] * 0.4);
        }
      }
  }
  if (gt) {
    const auto m = mask_of(*gt);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        if (outline(m, x, y)) {
          uint8_t* p = &rgb[3 * (static_cast<size_t>(y) * w + x)];
          p[0] = 255, p[1] = 0, p[2] = 255;
        }
  }
  pb::write_rgb8_png(path, w, h, rgb);
}

// True if `path` is a PLY file whose header declares zero vertices or zero
// faces (assimp refuses such files).
bool ply_declares_no_geometry(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  if (!std::getline(in, line) || line.rfind("ply", 0) != 0) return false;
  long vertices = -1, faces = -1;
  for (int n = 0; n < 200 && std::getline(in, line); ++n) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line == "end_header") return vertices == 0 || faces == 0;
    std::istringstream ss(line);
    std::string word, kind;
    long count = -1;
    if (ss >> word >> kind >> count && word == "element") {
      if (kind == "vertex") vertices = count;
      if (kind == "face") faces = count;
    }
  }
  return false;
}

nlohmann::ordered_json times_json(const pb::StageTimes& t) {
  return {{"preprocess", t.preprocess}, {"describe", t.describe}, {"match", t.match},
          {"group", t.group},           {"initial_pose", t.initial_pose}, {"refine", t.refine},
          {"verify", t.verify},         {"total", t.total()}};
}

struct Options {
  std::string dataset_dir, split, object, method, refine, config, overlay, cache = default_cache_dir(),
                                                                         scenario = "table";
  int scene = -1, image = -1, views = 0;
  long long seed = -1;
  bool json = false;
};

void add_options(CLI::App& app, Options& o) {
  app.add_option("--dataset", o.dataset_dir, "BOP dataset root (models/, test/ ...)")->required();
  app.add_option("--split", o.split, "split folder (default: test if present, else the first)");
  app.add_option("--scene", o.scene, "scene id")->required();
  app.add_option("--image", o.image, "image id")->required();
  app.add_option("--object", o.object, "object id, obj_XXXXXX or name (models_info.json)")->required();
  app.add_option("--method", o.method, "descriptor: fpfh shot cvfh esf cesf ourcvfh ppf (default: config, else fpfh)");
  app.add_option("--refine", o.refine, "refinement: none icp icp_lm icp_plane gicp ndt (default: config, else icp)");
  app.add_option("--views", o.views, "training views (1, 8, 12 or N on a sphere)")->check(CLI::PositiveNumber);
  app.add_option("--config", o.config, "recognition settings YAML (sections descriptor, refinement, views, "
                                       "preprocess, local, global, ppf, refine, verify, seed)");
  app.add_option("--seed", o.seed, "seed of every random choice (overrides the config)")->check(CLI::NonNegativeNumber);
  app.add_option("--overlay", o.overlay, "write a PNG: the model at the estimated pose over the colour-mapped depth");
  app.add_option("--cache", o.cache, "training cache folder ('' = no cache; default $POSEBENCH_CACHE or ~/.cache/posebench/train)");
  app.add_option("--scenario", o.scenario, "thresholds for 'correct': table (50 mm) or warehouse (100 mm)");
  app.add_flag("--json", o.json, "print one JSON object");
}

// Settings from --config, then the flags.
void settings_from(const Options& o, pb::RecognitionSettings& s) {
  if (!o.config.empty()) s = pb::parse_recognition_settings(pb::YamlNode::load_file(o.config), s);
  if (!o.method.empty()) s.descriptor = pb::descriptor_entry(o.method, "", "--method").name;
  if (!o.refine.empty()) s.refinement = pb::refinement_entry(o.refine, "", "--refine").name;
  if (o.views > 0) s.views.views = o.views;
  if (o.seed >= 0) s.seed = static_cast<uint64_t>(o.seed);
}

// The ground-truth instance of the object closest to the estimate, and the
// thesis's errors against it.
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
    const auto syms = pb::symmetry_transformations(info);
    pb::ThesisErrorOptions eo;
    eo.thresholds = thr;
    double best = std::numeric_limits<double>::infinity();
    for (const auto& g : im.gt) {
      if (g.obj_id != obj_id) continue;
      const pb::ThesisErrors e = pb::thesis_errors(res.T_cam_model, g.T_cam_model, syms, eo);
      const double key = std::max(e.translation_mm / thr.translation_mm, e.rotation / thr.rotation);
      if (key < best) {
        best = key;
        ev.err = e;
        ev.gt_pose = g.T_cam_model;
        ev.has_gt = true;
      }
    }
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

// What the command prints, in either form.
struct Outcome {
  const Options& o;
  const pb::RecognitionSettings& s;
  const pb::RecognitionResult& res;
  const Evaluation& ev;
  const pb::ImageInfo& im;
  int obj_id;
  std::string model_name;
  int train_views;
  double train_s;
  bool from_cache;
};

std::string json_output(const Outcome& x) {
  const bool ok = x.res.status == "ok";
  nlohmann::ordered_json j;
  j["status"] = x.res.status;
  if (!x.res.message.empty()) j["message"] = x.res.message;
  j["dataset"] = x.o.dataset_dir;
  j["split"] = x.o.split;
  j["scene"] = x.o.scene;
  j["image"] = x.o.image;
  j["object"] = {{"id", x.obj_id}, {"name", x.model_name}};
  j["method"] = x.s.descriptor;
  j["refinement"] = x.s.refinement;
  if (ok) {
    std::vector<double> R, t;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) R.push_back(x.res.T_cam_model.R(r, c));
    for (int r = 0; r < 3; ++r) t.push_back(x.res.T_cam_model.t[r]);
    j["R"] = R;
    j["t"] = t;
  } else {
    j["R"] = nullptr;
    j["t"] = nullptr;
  }
  j["score"] = x.res.score;
  j["inliers"] = x.res.inliers;
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
  if (!x.o.overlay.empty()) j["overlay"] = x.o.overlay;
  return j.dump() + "\n";
}

std::string text_output(const Outcome& x, const pb::ThesisThresholds& thr) {
  const pb::RecognitionResult& res = x.res;
  std::ostringstream o;
  o << std::setprecision(6);
  o << "object " << x.model_name << " (id " << x.obj_id << ") in " << x.o.split << " scene " << x.o.scene
    << " image " << x.o.image << ": " << x.s.descriptor << " + " << x.s.refinement << "\n";
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
  }
  o << "times (s): preprocess " << res.times.preprocess << ", describe " << res.times.describe << ", match "
    << res.times.match << ", group " << res.times.group << ", initial pose " << res.times.initial_pose
    << ", refine " << res.times.refine << ", verify " << res.times.verify << "; total " << res.times.total()
    << "\n";
  if (x.ev.has_gt)
    o << "errors vs ground truth (symmetry-aware): translation " << x.ev.err.translation_mm << " mm, 1-|p.q| "
      << x.ev.err.rotation << ", angle " << x.ev.err.rotation_deg << " deg -> "
      << (x.ev.correct ? "correct" : "not correct") << " (" << x.o.scenario << " thresholds " << thr.translation_mm
      << " mm, " << thr.rotation << ")\n";
  else if (x.ev.gt_instances == 0 && !x.im.gt.empty())
    o << "ground truth: the object is not annotated in this image\n";
  else if (x.im.gt.empty())
    o << "ground truth: none for this image\n";
  if (!x.o.overlay.empty()) o << "overlay: " << x.o.overlay << "\n";
  return o.str();
}

}  // namespace

static pb::cli::Command recognize_cmd(
    "recognize", "recognize one object in one image of a BOP dataset", [](int argc, char** argv) {
      CLI::App app{"Recognizes one object in one depth image of a BOP-layout dataset and prints its pose, "
                   "inliers, stage times and, where ground truth exists, the errors."};
      Options o;
      add_options(app, o);
      PB_CLI_PARSE(app, argc, argv);

      pb::RecognitionSettings s;
      settings_from(o, s);
      const pb::ThesisThresholds thr = pb::thesis_thresholds(o.scenario);

      const pb::BopDataset ds(o.dataset_dir);
      if (o.split.empty()) {
        const auto sp = ds.splits();
        o.split = std::find(sp.begin(), sp.end(), "test") != sp.end() ? "test" : sp.front();
      }
      const int obj_id = ds.resolve_object(o.object);
      const pb::ModelInfo& info = ds.model_info(obj_id);
      const pb::SceneInfo sc = ds.load_scene(o.split, o.scene);
      const auto im_it = sc.images.find(o.image);
      if (im_it == sc.images.end())
        throw pb::InputError(o.dataset_dir + "/" + o.split + "/" + pb::bop_id(o.scene) + "/scene_camera.json", "image",
                             "no image " + std::to_string(o.image) + " in scene " + std::to_string(o.scene));
      pb::ImageInfo im = im_it->second;
      const pb::DepthImage depth = ds.load_depth(o.split, o.scene, im);
      if (im.K.width <= 0 || im.K.height <= 0) {
        im.K.width = depth.width;
        im.K.height = depth.height;
      }
      pb::Mesh mesh;
      try {
        mesh = ds.load_model(obj_id);
      } catch (const pb::InputError&) {
        // A well-formed PLY without vertices or faces is an empty model (the
        // result says so); a missing or broken file stays an input error.
        if (!ply_declares_no_geometry(ds.model_path(obj_id))) throw;
      }
      const std::string model_name = info.name.empty() ? "obj_" + pb::bop_id(obj_id) : info.name;

      pb::Timer train_timer;
      pb::TrainOptions topt;
      topt.cache_dir = o.cache;
      bool from_cache = false;
      const auto model = pb::train_model(pb::training_views(mesh, s.views, model_name), s, topt, &from_cache);
      const double train_s = train_timer.seconds();
      const pb::RecognitionResult res = pb::recognize(depth, im.K, *model, s);
      const Evaluation ev = evaluate(res, im, obj_id, info, thr);
      if (!o.overlay.empty())
        write_overlay(o.overlay, depth, im.K, mesh, res.status == "ok" ? &res.T_cam_model : nullptr,
                      ev.gt_instances > 0 ? &ev.gt_pose : nullptr);
      const Outcome x{o, s, res, ev, im, obj_id, model_name, pb::trained_model_info(*model).views, train_s, from_cache};
      std::cout << (o.json ? json_output(x) : text_output(x, thr));
      return 0;
    });
