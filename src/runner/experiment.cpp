#include "runner/experiment.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <set>

#include "core/error.h"
#include "core/random.h"
#include "io/bop.h"
#include "recognition/pipeline.h"
#include "recognition/registry.h"

namespace fs = std::filesystem;

namespace pb {

std::string hash_hex(const std::string& text) {
  uint64_t h = 1469598103934665603ull;
  for (unsigned char c : text) {
    h ^= c;
    h *= 1099511628211ull;
  }
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

// YAML -> JSON (scalars typed by their YAML reading: bool, int, float, string).
static nlohmann::json to_json(const YAML::Node& n) {
  if (n.IsMap()) {
    nlohmann::json j = nlohmann::json::object();
    for (const auto& kv : n) j[kv.first.as<std::string>()] = to_json(kv.second);
    return j;
  }
  if (n.IsSequence()) {
    nlohmann::json j = nlohmann::json::array();
    for (const auto& e : n) j.push_back(to_json(e));
    return j;
  }
  if (!n.IsDefined() || n.IsNull()) return nullptr;
  const std::string s = n.Scalar();
  if (n.Tag() == "!") return s;  // quoted
  bool b;
  if (YAML::convert<bool>::decode(n, b) && s != "0" && s != "1") return b;
  try {
    size_t pos = 0;
    long long v = std::stoll(s, &pos);
    if (pos == s.size()) return v;
  } catch (...) {
  }
  try {
    size_t pos = 0;
    double v = std::stod(s, &pos);
    if (pos == s.size()) return v;
  } catch (...) {
  }
  return s;
}

// Sets a dotted path ("global.top_k") in a settings JSON object.
static void set_path(nlohmann::json& j, const std::string& path, const nlohmann::json& v) {
  nlohmann::json* cur = &j;
  size_t start = 0;
  while (true) {
    const size_t dot = path.find('.', start);
    const std::string part = path.substr(start, dot == std::string::npos ? std::string::npos : dot - start);
    if (dot == std::string::npos) {
      (*cur)[part] = v;
      return;
    }
    if (!cur->contains(part) || !(*cur)[part].is_object()) (*cur)[part] = nlohmann::json::object();
    cur = &(*cur)[part];
    start = dot + 1;
  }
}

static void merge(nlohmann::json& base, const nlohmann::json& over) {
  for (auto it = over.begin(); it != over.end(); ++it) {
    if (it.value().is_object() && base.contains(it.key()) && base[it.key()].is_object())
      merge(base[it.key()], it.value());
    else
      base[it.key()] = it.value();
  }
}

static std::string resolve(const std::string& base_file, const std::string& p) {
  if (p.empty() || fs::path(p).is_absolute()) return p;
  // Paths are relative to the current directory when they exist there (the
  // usual case: run from the project root), else to the config's folder.
  if (fs::exists(p)) return p;
  return (fs::path(base_file).parent_path() / p).string();
}

ExperimentConfig load_experiment(const std::string& path) {
  const YamlNode root = YamlNode::load_file(path);
  root.check_keys({"name", "seed", "object", "scenes", "descriptors", "refinements", "grid", "added_noise_mm",
                   "settings", "thresholds", "timeout_s", "registration_only", "perturb_deg", "perturb_mm",
                   "description", "report"});
  ExperimentConfig c;
  c.file = path;
  c.name = root.get_or<std::string>("name", fs::path(path).stem().string());
  c.seed = root.get_or<unsigned long long>("seed", 1);
  c.object = root.get<std::string>("object");
  c.registration_only = root.get_or<bool>("registration_only", false);
  c.perturb_deg = root.get_nonnegative("perturb_deg", c.perturb_deg);
  c.perturb_mm = root.get_nonnegative("perturb_mm", c.perturb_mm);
  c.timeout_s = root.get_positive("timeout_s", c.timeout_s);

  const auto known_desc = descriptor_names();
  const auto known_ref = refinement_names();
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
  for (const auto& r : c.refinements)
    if (std::find(known_ref.begin(), known_ref.end(), r) == known_ref.end())
      root["refinements"].fail("unknown refinement '" + r + "'");
  c.added_noise_mm = root.get_or<std::vector<double>>("added_noise_mm", c.added_noise_mm);
  for (double n : c.added_noise_mm)
    if (!(n >= 0)) root["added_noise_mm"].fail("noise levels must be non-negative");

  if (root.has("thresholds")) {
    const YamlNode t = root["thresholds"];
    t.check_keys({"table_translation_mm", "warehouse_translation_mm", "rotation_1mpq"});
    c.thresholds.table_translation_mm = t.get_positive("table_translation_mm", c.thresholds.table_translation_mm);
    c.thresholds.warehouse_translation_mm =
        t.get_positive("warehouse_translation_mm", c.thresholds.warehouse_translation_mm);
    c.thresholds.rotation_1mpq = t.get_positive("rotation_1mpq", c.thresholds.rotation_1mpq);
  }

  // Base settings: validated through the recognition settings parser on the
  // original node, so errors carry the right line.
  if (root.has("settings")) {
    parse_recognition_settings(root["settings"]);
    c.settings = to_json(root["settings"].raw());
  }

  if (root.has("grid")) {
    const YamlNode g = root["grid"];
    if (!g.is_map()) g.fail("expected a mapping of setting path -> list of values");
    for (const auto& key : g.keys()) {
      const YamlNode v = g[key];
      if (!v.is_sequence() || v.size() == 0) v.fail("expected a non-empty list of values");
      std::vector<nlohmann::json> vals;
      for (size_t i = 0; i < v.size(); ++i) {
        vals.push_back(to_json(v.at(i).raw()));
        nlohmann::json probe = c.settings;
        set_path(probe, key, vals.back());
        try {
          parse_recognition_settings(YamlNode::load_string(probe.dump(), path));
        } catch (const InputError& e) {
          throw InputError(path, "grid." + key, "line " + std::to_string(v.line()) + ": " + e.what());
        }
      }
      c.grid.emplace_back(key, vals);
    }
  }

  if (root.has("report")) {
    const YamlNode r = root["report"];
    r.check_keys({"reference_table", "plot_x", "columns"});
    c.report = to_json(r.raw());
  }

  const YamlNode scenes = root["scenes"];
  if (!scenes.is_sequence() || scenes.size() == 0) scenes.fail("expected a non-empty list of scenes");
  std::set<std::string> names;
  for (size_t i = 0; i < scenes.size(); ++i) {
    const YamlNode s = scenes.at(i);
    s.check_keys({"name", "generate", "dataset", "split", "scene_ids", "images", "scenario", "generator",
                  "settings", "refinements"});
    SceneSource src;
    src.generate = resolve(path, s.get_or<std::string>("generate", ""));
    src.dataset = resolve(path, s.get_or<std::string>("dataset", ""));
    if (src.generate.empty() == src.dataset.empty())
      s.fail("give exactly one of 'generate' (a scene config) or 'dataset' (a BOP dataset)");
    if (!src.generate.empty() && !fs::exists(src.generate))
      s["generate"].fail("scene config not found: " + src.generate);
    src.name = s.get_or<std::string>(
        "name", fs::path(src.generate.empty() ? src.dataset : src.generate).stem().string());
    if (!names.insert(src.name).second) s["name"].fail("duplicate scene name '" + src.name + "'");
    src.split = s.get_or<std::string>("split", "test");
    src.scene_ids = s.get_or<std::vector<int>>("scene_ids", {});
    src.images = s.get_or<int>("images", 0);
    if (src.images < 0) s["images"].fail("must be non-negative");
    src.scenario = s.get_or<std::string>(
        "scenario", src.name.rfind("warehouse", 0) == 0 ? std::string("warehouse") : std::string("table"));
    if (src.scenario != "table" && src.scenario != "warehouse")
      s["scenario"].fail("must be 'table' or 'warehouse'");
    src.refinements = s.get_or<std::vector<std::string>>("refinements", {});
    for (const auto& r : src.refinements)
      if (std::find(known_ref.begin(), known_ref.end(), r) == known_ref.end())
        s["refinements"].fail("unknown refinement '" + r + "'");
    if (s.has("generator")) {
      if (src.generate.empty()) s["generator"].fail("only valid with 'generate'");
      src.generator_overrides = to_json(s["generator"].raw());
    }
    if (s.has("settings")) {
      parse_recognition_settings(s["settings"]);
      src.settings = to_json(s["settings"].raw());
    }
    c.scenes.push_back(src);
  }

  nlohmann::json canon;
  canon["name"] = c.name;
  canon["seed"] = c.seed;
  canon["object"] = c.object;
  canon["descriptors"] = c.descriptors;
  canon["refinements"] = c.refinements;
  canon["added_noise_mm"] = c.added_noise_mm;
  canon["settings"] = c.settings;
  canon["registration_only"] = c.registration_only;
  canon["timeout_s"] = c.timeout_s;
  canon["perturb"] = {c.perturb_deg, c.perturb_mm};
  canon["thresholds"] = {c.thresholds.table_translation_mm, c.thresholds.warehouse_translation_mm,
                         c.thresholds.rotation_1mpq};
  for (const auto& [k, v] : c.grid) canon["grid"].push_back({k, v});
  for (const auto& s : c.scenes)
    canon["scenes"].push_back({{"name", s.name}, {"generate", s.generate}, {"dataset", s.dataset},
                               {"split", s.split}, {"scene_ids", s.scene_ids}, {"images", s.images},
                               {"scenario", s.scenario}, {"generator", s.generator_overrides},
                               {"refinements", s.refinements},
                               {"settings", s.settings}});
  canon["report"] = c.report;
  c.canonical = canon;
  c.hash = hash_hex(canon.dump());
  return c;
}

std::vector<Trial> expand_trials(const ExperimentConfig& cfg) {
  // Grid points: cartesian product in declaration order.
  std::vector<nlohmann::json> points{nlohmann::json::object()};
  for (const auto& [key, vals] : cfg.grid) {
    std::vector<nlohmann::json> next;
    for (const auto& p : points)
      for (const auto& v : vals) {
        nlohmann::json q = p;
        q[key] = v;
        next.push_back(q);
      }
    points = next;
  }

  std::vector<Trial> trials;
  for (const auto& src : cfg.scenes) {
    BopDataset ds(src.dataset);
    std::vector<int> sids = src.scene_ids.empty() ? ds.scene_ids(src.split) : src.scene_ids;
    for (int sid : sids) {
      const SceneInfo scene = ds.load_scene(src.split, sid);
      int taken = 0;
      for (const auto& [im_id, im] : scene.images) {
        if (src.images > 0 && taken >= src.images) break;
        ++taken;
        const auto& refinements = src.refinements.empty() ? cfg.refinements : src.refinements;
        for (const auto& d : cfg.descriptors)
          for (const auto& r : refinements)
            for (const auto& p : points)
              for (double noise : cfg.added_noise_mm) {
                Trial t;
                t.scene_name = src.name;
                t.scenario = src.scenario;
                t.dataset = src.dataset;
                t.split = src.split;
                t.scene_id = sid;
                t.im_id = im_id;
                t.descriptor = d;
                t.refinement = r;
                t.params = p;
                t.added_noise_mm = noise;
                nlohmann::json s = cfg.settings;
                merge(s, src.settings);
                for (auto it = p.begin(); it != p.end(); ++it) set_path(s, it.key(), it.value());
                s["descriptor"] = d == "none" ? "fpfh" : d;
                s["refinement"] = r;
                t.settings = s;
                char buf[64];
                std::snprintf(buf, sizeof buf, "%d/%d", sid, im_id);
                t.key = src.name + "/" + buf + "/" + d + "/" + r + "/" + p.dump() + "/noise=" +
                        nlohmann::json(noise).dump();
                const uint64_t h = std::stoull(hash_hex(t.key), nullptr, 16);
                t.seed = derive_seed(cfg.seed, {h});
                trials.push_back(std::move(t));
              }
      }
    }
  }
  return trials;
}

}  // namespace pb
