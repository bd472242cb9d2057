#include "runner/experiment.h"

#include <algorithm>
#include <cstdlib>
#include <climits>
#include <cstdio>
#include <filesystem>
#include <map>
#include <set>

#include "core/error.h"
#include "runner/experiment_internal.h"
#include "core/hash.h"
#include "io/symmetry_yaml.h"
#include "core/random.h"
#include "io/bop.h"
#include "io/cloud.h"
#include "recognition/pipeline.h"
#include "recognition/registry.h"
#include "scenes/views.h"

namespace fs = std::filesystem;

namespace pb {

using namespace experiment_detail;

namespace {

// name, seed, object, descriptors, refinements, noise, time limit, registration_only.
void parse_header(const YamlNode& root, const std::string& path, ExperimentConfig& c) {

  c.name = root.get_or<std::string>("name", fs::path(path).stem().string());
  c.seed = root.get_or<unsigned long long>("seed", 1);
  c.object = root.get<std::string>("object");
  c.registration_only = root.get_or<bool>("registration_only", false);
  c.perturb_deg = root.get_nonnegative("perturb_deg", c.perturb_deg);
  c.perturb_mm = root.get_nonnegative("perturb_mm", c.perturb_mm);
  c.timeout_s = root.get_positive("timeout_s", c.timeout_s);

  const auto known_desc = descriptor_names();
  if (c.registration_only) {
    c.descriptors = root.get_or<std::vector<std::string>>("descriptors", {"none"});
  } else {
    c.descriptors = root.get<std::vector<std::string>>("descriptors");
    if (c.descriptors.empty()) root["descriptors"].fail("needs at least one descriptor");
    for (const auto& d : c.descriptors)
      if (std::find(known_desc.begin(), known_desc.end(), d) == known_desc.end())
        root["descriptors"].fail("unknown descriptor '" + d + "'");
  }
  c.refinements = root.get_or<std::vector<std::string>>("refinements", c.refinements);
  check_refinements(root["refinements"], c.refinements);
  c.added_noise_mm = root.get_or<std::vector<double>>("added_noise_mm", c.added_noise_mm);
  for (double n : c.added_noise_mm)
    if (!(n >= 0)) root["added_noise_mm"].fail("noise levels must be non-negative");

}

void parse_thresholds(const YamlNode& root, ExperimentConfig& c) {
  if (root.has("thresholds")) {
    const YamlNode t = root["thresholds"];
    t.check_keys({"table_translation_mm", "warehouse_translation_mm", "rotation_1mpq"});
    c.thresholds.table_translation_mm = t.get_positive("table_translation_mm", c.thresholds.table_translation_mm);
    c.thresholds.warehouse_translation_mm =
        t.get_positive("warehouse_translation_mm", c.thresholds.warehouse_translation_mm);
    c.thresholds.rotation_1mpq = t.get_positive("rotation_1mpq", c.thresholds.rotation_1mpq);
  }

}

// The grid point's settings: `base` with each (path, value) applied;
// errors name the grid entry and its line.
RecognitionSettings with_grid_point(RecognitionSettings s, const std::vector<std::pair<std::string, YamlNode>>& point,
                                    const std::string& file) {
  for (const auto& [path, value] : point) {
    try {
      s = apply_setting(s, path, value);
    } catch (const InputError& e) {
      throw InputError(file, "grid." + path, "line " + std::to_string(value.line()) + ": " + e.what());
    }
  }
  return s;
}

// Base settings and the grid, read from the config's own nodes, so errors
// carry the right line; each grid value is checked over the base settings.
void parse_settings_and_grid(const YamlNode& root, const std::string& path, ExperimentConfig& c) {
  c.settings = parse_recognition_settings(root["settings"]);
  if (!root.has("grid")) return;
  const YamlNode g = root["grid"];
  if (!g.is_map()) g.fail("expected a mapping of setting path -> list of values");
  for (const auto& key : g.keys()) {
    const YamlNode v = g[key];
    if (!v.is_sequence() || v.size() == 0) v.fail("expected a non-empty list of values");
    GridAxis axis{key, {}};
    for (size_t i = 0; i < v.size(); ++i) {
      axis.values.push_back(v.at(i));
      with_grid_point(c.settings, {{key, v.at(i)}}, path);
    }
    c.grid.push_back(std::move(axis));
  }
}

}  // namespace

std::vector<Judgement> parse_judgements(const YamlNode& js) {
  std::vector<Judgement> out;
  if (!js.defined()) return out;
  if (!js.is_map()) js.fail("expected a mapping of name -> {description, symmetries_discrete, symmetries_continuous}");
  for (const auto& name : js.keys()) {
    const YamlNode j = js[name];
    j.check_keys({"description", "symmetries_discrete", "symmetries_continuous"});
    Judgement jd;
    jd.name = name;
    jd.description = j.get_or<std::string>("description", "");
    read_symmetries(j, jd.symmetries_discrete, jd.symmetries_continuous);
    out.push_back(jd);
  }
  return out;
}

nlohmann::json judgements_json(const std::vector<Judgement>& js) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& j : js) {
    nlohmann::json d = nlohmann::json::array(), cont = nlohmann::json::array();
    for (const Mat4& m : j.symmetries_discrete) {
      std::vector<double> v;
      for (int r = 0; r < 4; ++r)
        for (int k = 0; k < 4; ++k) v.push_back(m(r, k));
      d.push_back(v);
    }
    for (const auto& cs : j.symmetries_continuous)
      cont.push_back({{"axis", {cs.axis.x(), cs.axis.y(), cs.axis.z()}},
                      {"offset", {cs.offset.x(), cs.offset.y(), cs.offset.z()}}});
    out.push_back({{"name", j.name}, {"symmetries_discrete", d}, {"symmetries_continuous", cont}});
  }
  return out;
}

namespace {

// The parsed config as JSON: what experiment.json keeps and the hash covers
// (the settings sections as written in `root`).
nlohmann::json canonical(const ExperimentConfig& c, const YamlNode& root) {
  const auto as_written = [](const YamlNode& n) { return n.has("settings") ? n["settings"].json() : nlohmann::json::object(); };
  nlohmann::json canon;
  canon["name"] = c.name;
  canon["seed"] = c.seed;
  canon["object"] = c.object;
  canon["descriptors"] = c.descriptors;
  canon["refinements"] = c.refinements;
  canon["added_noise_mm"] = c.added_noise_mm;
  canon["settings"] = as_written(root);
  canon["registration_only"] = c.registration_only;
  canon["timeout_s"] = c.timeout_s;
  canon["perturb"] = {c.perturb_deg, c.perturb_mm};
  canon["thresholds"] = {c.thresholds.table_translation_mm, c.thresholds.warehouse_translation_mm,
                         c.thresholds.rotation_1mpq};
  for (const GridAxis& axis : c.grid) {
    nlohmann::json values = nlohmann::json::array();
    for (const YamlNode& v : axis.values) values.push_back(v.json());
    canon["grid"].push_back({axis.path, values});
  }
  for (size_t i = 0; i < c.scenes.size(); ++i) {
    const SceneSource& s = c.scenes[i];
    canon["scenes"].push_back({{"name", s.name}, {"generate", s.generate}, {"dataset", s.dataset},
                               {"split", s.split}, {"scene_ids", s.scene_ids}, {"images", s.images},
                               {"scenario", s.scenario}, {"generator", s.generator_overrides},
                               {"refinements", s.refinements},
                               {"settings", as_written(root["scenes"].at(i))}});
  }
  for (size_t i = 0; i < c.scenes.size(); ++i) {  // only when given: older hashes stay
    if (!c.scenes[i].targets.empty()) canon["scenes"][i]["targets"] = c.scenes[i].targets;
    if (!c.scenes[i].clouds.empty()) canon["scenes"][i]["clouds"] = {c.scenes[i].clouds, c.scenes[i].cloud};
    if (!c.scenes[i].twin_of.empty()) canon["scenes"][i]["twin_of"] = c.scenes[i].twin_of;
    if (c.scenes[i].image_stride != 1) canon["scenes"][i]["image_stride"] = c.scenes[i].image_stride;
    if (!c.scenes[i].twin_sensor.empty())
      canon["scenes"][i]["twin"] = {{"sensor", c.scenes[i].twin_sensor},
                                    {"keep_background", c.scenes[i].twin_keep_background},
                                    {"seed", c.scenes[i].twin_seed}};
  }
  canon["report"] = c.report;
  if (!c.judgements.empty()) canon["judgements"] = judgements_json(c.judgements);
  return canon;
}

}  // namespace

ExperimentConfig load_experiment(const std::string& path) {
  const YamlNode root = YamlNode::load_file(path);
  root.check_keys({"name", "seed", "object", "scenes", "descriptors", "refinements", "grid", "added_noise_mm",
                   "settings", "thresholds", "timeout_s", "registration_only", "perturb_deg", "perturb_mm",
                   "description", "report", "judgements"});
  ExperimentConfig c;
  c.file = path;
  parse_header(root, path, c);
  parse_thresholds(root, c);
  parse_settings_and_grid(root, path, c);
  if (root.has("report")) {
    const YamlNode r = root["report"];
    r.check_keys({"reference_table", "plot_x", "columns"});
    c.report = r.json();
  }

  const YamlNode scenes = root["scenes"];
  if (!scenes.is_sequence() || scenes.size() == 0) scenes.fail("expected a non-empty list of scenes");
  std::set<std::string> names;
  for (size_t i = 0; i < scenes.size(); ++i) c.scenes.push_back(parse_scene(scenes.at(i), path, c.settings, names));
  resolve_twins(scenes, c.scenes);
  if (c.object == kEveryTargetObject) {
    for (size_t i = 0; i < scenes.size(); ++i) {
      SceneSource& src = c.scenes[i];
      // A generated set lists its own targets (scene_test_targets).
      if (!src.generate.empty() && src.targets.empty()) src.targets = kGeneratedTargets;
      if (src.targets.empty() || (src.dataset.empty() && src.generate.empty() && src.twin_sensor.empty()))
        scenes.at(i).fail("'object: all' takes the objects from the scene's BOP test targets: give 'generate' "
                          "(the generated set lists its own), or 'dataset' and 'targets' (e.g. "
                          "test_targets_bop19.json)");
    }
    if (c.registration_only) root["registration_only"].fail("not with 'object: all'");
  }
  c.judgements = parse_judgements(root["judgements"]);
  c.canonical = canonical(c, root);
  c.hash = hash_hex(c.canonical.dump());
  return c;
}

namespace {

// A scene source's test targets for the experiment's object (every object
// with `object: all`): the file, and per listed (scene_id, im_id) the index
// of its first entry there (for errors) and its targets (obj_id,
// inst_count). Every scene must be in the split; that every image is in its
// scene is checked as expand_trials reads the scene (check_target_images).
struct ImageTargets {
  size_t first_entry = 0;
  std::vector<std::pair<int, int>> objects;  // (obj_id, inst_count)
};
struct Targets {
  std::string file;
  std::map<std::pair<int, int>, ImageTargets> images;
};

Targets read_targets(const SceneSource& src, const BopDataset& ds, const std::string& object) {
  Targets out;
  if (src.targets.empty()) return out;
  out.file = fs::path(src.targets).is_absolute() ? src.targets : (fs::path(src.dataset) / src.targets).string();
  if (std::error_code ec; !fs::is_regular_file(out.file, ec))
    throw InputError(out.file, "targets",
                     src.generate.empty() ? "test-targets file not found"
                                          : "test-targets file not found: the scene set was generated before "
                                            "posebench wrote it; delete the set's folder to generate it again");
  const bool every = object == kEveryTargetObject;
  const int obj = every ? 0 : ds.resolve_object(object);
  const auto targets = read_test_targets(out.file);
  const auto scenes = ds.scene_ids(src.split);
  for (size_t i = 0; i < targets.size(); ++i) {
    const TestTarget& t = targets[i];
    if (!every && t.obj_id != obj) continue;
    if (std::find(scenes.begin(), scenes.end(), t.scene_id) == scenes.end())
      throw InputError(out.file, "[" + std::to_string(i) + "].scene_id",
                       "scene " + std::to_string(t.scene_id) + " is not in split '" + src.split + "'");
    if (every && !ds.models().count(t.obj_id))
      throw InputError(out.file, "[" + std::to_string(i) + "].obj_id",
                       "object " + std::to_string(t.obj_id) + " is not in the dataset's models_info.json");
    auto [it, fresh] = out.images.try_emplace({t.scene_id, t.im_id});
    if (fresh) it->second.first_entry = i;
    it->second.objects.push_back({t.obj_id, t.inst_count});
  }
  if (out.images.empty())
    throw InputError(out.file, "obj_id", "no target for object '" + object + "' (obj_id " + std::to_string(obj) + ")");
  return out;
}

void check_target_images(const Targets& targets, const SceneInfo& scene) {
  for (auto it = targets.images.lower_bound({scene.scene_id, INT_MIN});
       it != targets.images.end() && it->first.first == scene.scene_id; ++it)
    if (!scene.images.count(it->first.second))
      throw InputError(targets.file, "[" + std::to_string(it->second.first_entry) + "].im_id",
                       "image " + std::to_string(it->first.second) + " is not in scene " + std::to_string(scene.scene_id));
}

// A grid point: each axis's path with one of its values.
struct GridPoint {
  std::vector<std::pair<std::string, YamlNode>> values;
  nlohmann::json params = nlohmann::json::object();  // path -> value (trial keys and records)
};

// One trial: the scene source's image, object (obj_id 0: the experiment's;
// with an inst_count, verify.max_instances is set to it), method, grid
// point and noise, its settings, key and seed.
Trial make_trial(const ExperimentConfig& cfg, const SceneSource& src, int sid, int im_id,
                 std::pair<int, int> target, const std::string& d, const std::string& r,
                 const GridPoint& point, double noise) {
  const nlohmann::json& p = point.params;
  const auto [obj_id, inst_count] = target;
  Trial t;
  t.scene_name = src.name;
  t.scenario = src.scenario;
  t.dataset = src.dataset;
  t.split = src.split;
  t.scene_id = sid;
  t.im_id = im_id;
  t.obj_id = obj_id;
  t.inst_count = inst_count;
  t.descriptor = d;
  t.refinement = r;
  t.params = p;
  t.added_noise_mm = noise;
  RecognitionSettings s = with_grid_point(src.settings, point.values, cfg.file);
  s.descriptor = d == "none" ? "fpfh" : d;
  s.refinement = r;
  if (inst_count > 0) s.verify.max_instances = inst_count;
  t.settings = s;
  char buf[64];
  std::snprintf(buf, sizeof buf, "%d/%d", sid, im_id);
  t.key = src.name + "/" + buf + "/" + d + "/" + r + "/" + p.dump() + "/noise=" + nlohmann::json(noise).dump();
  if (obj_id > 0) t.key += "/obj=" + std::to_string(obj_id);
  // The trial's random stream: stream_id (core/hash.h) keeps the seeds, and
  // so every recorded result, as they are.
  t.seed = derive_seed(cfg.seed, {stream_id(t.key)});
  return t;
}

}  // namespace

std::vector<Trial> expand_trials(const ExperimentConfig& cfg) {
  // Grid points: cartesian product in declaration order.
  std::vector<GridPoint> points(1);
  for (const GridAxis& axis : cfg.grid) {
    std::vector<GridPoint> next;
    for (const GridPoint& p : points)
      for (const YamlNode& v : axis.values) {
        GridPoint q = p;
        q.values.emplace_back(axis.path, v);
        q.params[axis.path] = v.json();
        next.push_back(std::move(q));
      }
    points = std::move(next);
  }

  std::vector<Trial> trials;
  for (const auto& src : cfg.scenes) {
    const size_t first = trials.size();
    BopDataset ds(src.dataset);
    std::vector<int> sids = src.scene_ids.empty() ? ds.scene_ids(src.split) : src.scene_ids;
    const Targets targets = read_targets(src, ds, cfg.object);
    if (!src.targets.empty() && src.scene_ids.empty()) {
      sids.clear();
      for (const auto& [key, image] : targets.images)
        if (sids.empty() || sids.back() != key.first) sids.push_back(key.first);
    }
    for (int sid : sids) {
      const SceneInfo scene = ds.load_scene(src.split, sid);
      check_target_images(targets, scene);
      int taken = 0, seen = 0;
      for (const auto& [im_id, im] : scene.images) {
        if (!src.targets.empty() && targets.images.count({sid, im_id}) == 0) continue;
        if (seen++ % src.image_stride != 0) continue;
        if (src.images > 0 && taken >= src.images) break;
        ++taken;
        const auto& refinements = src.refinements.empty() ? cfg.refinements : src.refinements;
        // The image's objects: the experiment's, or each test target's
        // (obj_id, inst_count) with `object: all`.
        std::vector<std::pair<int, int>> objects{{0, 0}};
        if (cfg.object == kEveryTargetObject) objects = targets.images.at({sid, im_id}).objects;
        for (const auto& target : objects)
          for (const auto& d : cfg.descriptors)
            for (const auto& r : refinements)
              for (const auto& p : points)
                for (double noise : cfg.added_noise_mm)
                  trials.push_back(make_trial(cfg, src, sid, im_id, target, d, r, p, noise));
      }
    }
    // views.follow_scene needs the scene set's camera elevations: a set
    // without them fails here, before any trial runs, not in every trial.
    for (size_t i = first; i < trials.size(); ++i) {
      if (trials[i].settings.views.follow_scene) {
        scene_set_elevation_deg(src.dataset);  // InputError naming the file and the field
        break;
      }
    }
  }
  return trials;
}

}  // namespace pb
