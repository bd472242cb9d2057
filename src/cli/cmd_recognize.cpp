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

}  // namespace

static pb::cli::Command recognize_cmd(
    "recognize", "recognize one object in one image of a BOP dataset", [](int argc, char** argv) {
      CLI::App app{"Recognizes one object in one depth image of a BOP-layout dataset and prints its pose, "
                   "inliers, stage times and, where ground truth exists, the errors."};
      std::string dataset_dir, split, object, method, refine, config, overlay, cache = default_cache_dir(),
                                                                              scenario = "table";
      int scene = -1, image = -1, views = 0;
      long long seed = -1;
      bool json = false;
      app.add_option("--dataset", dataset_dir, "BOP dataset root (models/, test/ ...)")->required();
      app.add_option("--split", split, "split folder (default: test if present, else the first)");
      app.add_option("--scene", scene, "scene id")->required();
      app.add_option("--image", image, "image id")->required();
      app.add_option("--object", object, "object id, obj_XXXXXX or name (models_info.json)")->required();
      app.add_option("--method", method, "descriptor: fpfh shot cvfh esf cesf ourcvfh ppf (default: config, else fpfh)");
      app.add_option("--refine", refine, "refinement: none icp icp_lm icp_plane gicp ndt (default: config, else icp)");
      app.add_option("--views", views, "training views (1, 8, 12 or N on a sphere)")->check(CLI::PositiveNumber);
      app.add_option("--config", config, "recognition settings YAML (sections descriptor, refinement, views, "
                                         "preprocess, local, global, ppf, refine, verify, seed)");
      app.add_option("--seed", seed, "seed of every random choice (overrides the config)")->check(CLI::NonNegativeNumber);
      app.add_option("--overlay", overlay, "write a PNG: the model at the estimated pose over the colour-mapped depth");
      app.add_option("--cache", cache, "training cache folder ('' = no cache; default $POSEBENCH_CACHE or ~/.cache/posebench/train)");
      app.add_option("--scenario", scenario, "thresholds for 'correct': table (50 mm) or warehouse (100 mm)");
      app.add_flag("--json", json, "print one JSON object");
      PB_CLI_PARSE(app, argc, argv);

      pb::RecognitionSettings s;
      if (!config.empty()) s = pb::parse_recognition_settings(pb::YamlNode::load_file(config), s);
      if (!method.empty()) s.descriptor = method;
      if (!refine.empty()) s.refinement = refine;
      if (views > 0) s.views.views = views;
      if (seed >= 0) s.seed = static_cast<uint64_t>(seed);
      {
        const auto d = pb::descriptor_names(), r = pb::refinement_names();
        if (std::find(d.begin(), d.end(), s.descriptor) == d.end())
          throw pb::InputError("", "--method", "unknown descriptor '" + s.descriptor + "'");
        if (std::find(r.begin(), r.end(), s.refinement) == r.end())
          throw pb::InputError("", "--refine", "unknown refinement '" + s.refinement + "'");
      }
      const pb::ThesisThresholds thr = pb::thesis_thresholds(scenario);

      const pb::BopDataset ds(dataset_dir);
      if (split.empty()) {
        const auto sp = ds.splits();
        split = std::find(sp.begin(), sp.end(), "test") != sp.end() ? "test" : sp.front();
      }
      const int obj_id = ds.resolve_object(object);
      const pb::ModelInfo& info = ds.model_info(obj_id);
      const pb::SceneInfo sc = ds.load_scene(split, scene);
      const auto im_it = sc.images.find(image);
      if (im_it == sc.images.end())
        throw pb::InputError(dataset_dir + "/" + split + "/" + pb::bop_id(scene) + "/scene_camera.json", "image",
                             "no image " + std::to_string(image) + " in scene " + std::to_string(scene));
      pb::ImageInfo im = im_it->second;
      const pb::DepthImage depth = ds.load_depth(split, scene, im);
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
      topt.cache_dir = cache;
      topt.model_name = model_name;
      bool from_cache = false;
      const auto model = pb::train_model(mesh, s, topt, &from_cache);
      const double train_s = train_timer.seconds();
      const pb::RecognitionResult res = pb::recognize(depth, im.K, *model, s);
      const bool ok = res.status == "ok";

      // Ground truth: the instance of the object closest to the estimate.
      bool has_gt = false;
      pb::ThesisErrors err;
      pb::Pose gt_pose;
      int gt_instances = 0;
      for (const auto& g : im.gt) gt_instances += g.obj_id == obj_id;
      if (ok && gt_instances > 0) {
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
            err = e;
            gt_pose = g.T_cam_model;
            has_gt = true;
          }
        }
      } else if (gt_instances > 0) {
        for (const auto& g : im.gt)
          if (g.obj_id == obj_id) {
            gt_pose = g.T_cam_model;
            break;
          }
      }
      const bool correct = has_gt && pb::thesis_correct(err, thr);

      if (!overlay.empty())
        write_overlay(overlay, depth, im.K, mesh, ok ? &res.T_cam_model : nullptr, gt_instances > 0 ? &gt_pose : nullptr);

      if (json) {
        nlohmann::ordered_json j;
        j["status"] = res.status;
        if (!res.message.empty()) j["message"] = res.message;
        j["dataset"] = dataset_dir;
        j["split"] = split;
        j["scene"] = scene;
        j["image"] = image;
        j["object"] = {{"id", obj_id}, {"name", model_name}};
        j["method"] = s.descriptor;
        j["refinement"] = s.refinement;
        if (ok) {
          std::vector<double> R, t;
          for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) R.push_back(res.T_cam_model.R(r, c));
          for (int r = 0; r < 3; ++r) t.push_back(res.T_cam_model.t[r]);
          j["R"] = R;
          j["t"] = t;
        } else {
          j["R"] = nullptr;
          j["t"] = nullptr;
        }
        j["score"] = res.score;
        j["inliers"] = res.inliers;
        j["hypotheses"] = res.hypotheses.size();
        j["times"] = times_json(res.times);
        j["train"] = {{"seconds", train_s}, {"from_cache", from_cache}, {"views", pb::trained_model_info(*model).views}};
        j["ground_truth_instances"] = gt_instances;
        if (has_gt)
          j["errors"] = {{"translation_mm", err.translation_mm},
                         {"rotation", err.rotation},
                         {"rotation_deg", err.rotation_deg},
                         {"symmetry_aware", true},
                         {"symmetry", err.symmetry},
                         {"translation_mm_plain", err.translation_mm_plain},
                         {"rotation_plain", err.rotation_plain},
                         {"rotation_deg_plain", err.rotation_deg_plain},
                         {"scenario", scenario},
                         {"correct", correct}};
        if (!overlay.empty()) j["overlay"] = overlay;
        std::cout << j.dump() << "\n";
        return 0;
      }

      std::ostringstream o;
      o << std::setprecision(6);
      o << "object " << model_name << " (id " << obj_id << ") in " << split << " scene " << scene << " image " << image
        << ": " << s.descriptor << " + " << s.refinement << "\n";
      o << "training: " << pb::trained_model_info(*model).views << " views, " << train_s << " s"
        << (from_cache ? " (from cache)" : "") << "\n";
      o << "status: " << res.status;
      if (!res.message.empty()) o << " (" << res.message << ")";
      o << "\n";
      if (ok) {
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
      if (has_gt)
        o << "errors vs ground truth (symmetry-aware): translation " << err.translation_mm << " mm, 1-|p.q| "
          << err.rotation << ", angle " << err.rotation_deg << " deg -> " << (correct ? "correct" : "not correct")
          << " (" << scenario << " thresholds " << thr.translation_mm << " mm, " << thr.rotation << ")\n";
      else if (gt_instances == 0 && !im.gt.empty())
        o << "ground truth: the object is not annotated in this image\n";
      else if (im.gt.empty())
        o << "ground truth: none for this image\n";
      if (!overlay.empty()) o << "overlay: " << overlay << "\n";
      std::cout << o.str();
      return 0;
    });
