#include "scenes/scene_config.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

namespace pb {

namespace fs = std::filesystem;

std::string scenario_name(Scenario s) { return s == Scenario::table ? "table" : "warehouse"; }

SceneSettings default_scene_settings(Scenario s) {
  SceneSettings st;
  st.scenario = s;
  st.distractors.pool = {"milk_carton", "boletus", "box_small", "cylinder"};
  if (s == Scenario::warehouse) {
    st.distractors.pool = {"pallet", "box_large", "barrel"};
    st.camera.distance_mm = {2000, 5000};
    st.camera.elevation_deg = {5, 30};
    st.distractors.min_count = 0;
    st.distractors.max_count = 2;
  }
  return st;
}

namespace {

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

// Reads a range: a scalar (fixed value) or [lo, hi]. `positive` requires
// lo > 0, otherwise lo >= `min_value`; hi <= max_value.
void read_range(const YamlNode& parent, const std::string& key, ValueRange& r, bool positive,
                double min_value = 0.0, double max_value = 1e300) {
  if (!parent.has(key)) return;
  const YamlNode n = parent[key];
  ValueRange out;
  if (n.is_scalar()) {
    out.lo = out.hi = n.as<double>();
  } else if (n.is_sequence()) {
    if (n.size() != 2) n.fail("expected a value or a range [lo, hi]");
    out.lo = n.at(0).as<double>();
    out.hi = n.at(1).as<double>();
  } else {
    n.fail("expected a value or a range [lo, hi]");
  }
  if (!(std::isfinite(out.lo) && std::isfinite(out.hi))) n.fail("must be finite");
  if (positive && !(out.lo > 0)) n.fail("must be positive, got " + num(out.lo));
  if (!positive && !(out.lo >= min_value))
    n.fail("must be at least " + num(min_value) + ", got " + num(out.lo));
  if (!(out.hi <= max_value))
    n.fail("must be at most " + num(max_value) + ", got " + num(out.hi));
  if (out.lo > out.hi) n.fail("range [lo, hi] with lo > hi");
  r = out;
}

double read_probability(const YamlNode& parent, const std::string& key, double fallback) {
  const double v = parent.get_or<double>(key, fallback);
  if (!(v >= 0.0 && v <= 1.0)) parent[key].fail("must be in [0, 1], got " + num(v));
  return v;
}

int read_int_at_least(const YamlNode& parent, const std::string& key, int fallback, int min_value) {
  const int v = parent.get_or<int>(key, fallback);
  if (v < min_value)
    parent[key].fail("must be at least " + std::to_string(min_value) + ", got " + std::to_string(v));
  return v;
}

}  // namespace

SceneSettings parse_scene_settings(const YamlNode& root) {
  root.check_keys({"scenario", "description", "scene_id", "seed", "images", "sensor", "noise",
                   "depth_scale", "registry", "target", "target_upright_probability",
                   "min_target_visib", "distractors", "occlusion", "camera", "table", "warehouse",
                   "masks", "max_attempts"});
  const std::string scen = root.get<std::string>("scenario");
  Scenario scenario;
  if (scen == "table") scenario = Scenario::table;
  else if (scen == "warehouse") scenario = Scenario::warehouse;
  else root["scenario"].fail("unknown scenario '" + scen + "' (table | warehouse)");

  SceneSettings s = default_scene_settings(scenario);
  s.config_file = root.file();
  if (!s.config_file.empty()) s.name = fs::path(s.config_file).stem().string();
  root.read("description", s.description);
  s.scene_id = read_int_at_least(root, "scene_id", s.scene_id, 0);
  if (s.scene_id > 999999) root["scene_id"].fail("must be at most 999999");
  if (root.has("seed")) {
    const long long seed = root.get<long long>("seed");
    if (seed < 0) root["seed"].fail("must be non-negative");
    s.seed = static_cast<uint64_t>(seed);
  }
  s.images = read_int_at_least(root, "images", s.images, 1);
  if (s.images > 999999) root["images"].fail("must be at most 999999");

  if (root.has("sensor")) {
    s.sensor = parse_sensor(root["sensor"]);
  } else {
    s.sensor = sensor_profile("synthetic", root.file(), "sensor");
  }
  s.sensor_name = s.sensor.name;
  s.noise = root.has("noise") ? parse_noise(root["noise"], s.sensor.noise) : s.sensor.noise;
  s.depth_scale = root.get_positive("depth_scale", s.sensor.depth_scale);

  if (root.has("registry")) {
    s.registry = root.get<std::string>("registry");
    if (s.registry.empty()) root["registry"].fail("empty path");
    fs::path p(s.registry);
    if (p.is_relative() && !s.config_file.empty())
      s.registry = (fs::path(s.config_file).parent_path() / p).lexically_normal().string();
  }
  root.read("target", s.target);
  if (s.target.empty()) root["target"].fail("empty model name");
  s.target_upright_probability =
      read_probability(root, "target_upright_probability", s.target_upright_probability);
  s.min_target_visib = read_probability(root, "min_target_visib", s.min_target_visib);

  if (root.has("distractors")) {
    const YamlNode d = root["distractors"];
    d.check_keys({"pool", "count", "upright_probability"});
    if (d.has("pool")) s.distractors.pool = d.get<std::vector<std::string>>("pool");
    if (d.has("count")) {
      ValueRange r{double(s.distractors.min_count), double(s.distractors.max_count)};
      read_range(d, "count", r, false, 0.0, 100.0);
      if (r.lo != std::floor(r.lo) || r.hi != std::floor(r.hi)) d["count"].fail("must be whole numbers");
      s.distractors.min_count = static_cast<int>(r.lo);
      s.distractors.max_count = static_cast<int>(r.hi);
    }
    s.distractors.upright_probability =
        read_probability(d, "upright_probability", s.distractors.upright_probability);
  }
  if (s.distractors.max_count > 0 && s.distractors.pool.empty())
    root["distractors"].fail("count > 0 needs a non-empty pool");

  if (root.has("occlusion")) {
    const YamlNode o = root["occlusion"];
    if (o.is_scalar()) {
      const std::string v = o.as<std::string>();
      if (v != "none") o.fail("expected none, a range [lo, hi] or {visib_fract, probability}");
      s.occlusion.enabled = false;
    } else if (o.is_sequence()) {
      s.occlusion.enabled = true;
      read_range(root, "occlusion", s.occlusion.visib_fract, false, 0.0, 1.0);
    } else {
      o.check_keys({"visib_fract", "probability"});
      s.occlusion.enabled = true;
      read_range(o, "visib_fract", s.occlusion.visib_fract, false, 0.0, 1.0);
      s.occlusion.probability = read_probability(o, "probability", s.occlusion.probability);
    }
  }

  if (root.has("camera")) {
    const YamlNode c = root["camera"];
    c.check_keys({"distance_mm", "elevation_deg", "look_jitter"});
    read_range(c, "distance_mm", s.camera.distance_mm, true);
    read_range(c, "elevation_deg", s.camera.elevation_deg, false, -89.0, 89.0);
    s.camera.look_jitter = c.get_nonnegative("look_jitter", s.camera.look_jitter);
    if (s.camera.look_jitter > 1.0) c["look_jitter"].fail("must be at most 1");
  }
  if (root.has("table")) {
    const YamlNode t = root["table"];
    t.check_keys({"size_mm", "thickness_mm", "gap_mm"});
    s.table.size_mm = t.get_positive("size_mm", s.table.size_mm);
    s.table.thickness_mm = t.get_positive("thickness_mm", s.table.thickness_mm);
    s.table.gap_mm = t.get_nonnegative("gap_mm", s.table.gap_mm);
  }
  if (root.has("warehouse")) {
    const YamlNode w = root["warehouse"];
    w.check_keys({"object_size_mm", "wall_distance_mm", "wall_height_mm", "gap_mm"});
    read_range(w, "object_size_mm", s.warehouse.object_size_mm, true);
    read_range(w, "wall_distance_mm", s.warehouse.wall_distance_mm, true);
    s.warehouse.wall_height_mm = w.get_positive("wall_height_mm", s.warehouse.wall_height_mm);
    s.warehouse.gap_mm = w.get_nonnegative("gap_mm", s.warehouse.gap_mm);
  }
  root.read("masks", s.masks);
  s.max_attempts = read_int_at_least(root, "max_attempts", s.max_attempts, 1);
  return s;
}

SceneSettings load_scene_settings(const std::string& path) {
  return parse_scene_settings(YamlNode::load_file(path));
}

std::string scene_settings_json(const SceneSettings& s) {
  using nlohmann::ordered_json;
  auto range = [](const ValueRange& r) { return ordered_json::array({r.lo, r.hi}); };
  ordered_json j;
  j["name"] = s.name;
  j["config_file"] = s.config_file.empty() ? "" : fs::path(s.config_file).filename().string();
  j["description"] = s.description;
  j["scenario"] = scenario_name(s.scenario);
  j["scene_id"] = s.scene_id;
  j["seed"] = s.seed;
  j["images"] = s.images;
  const Intrinsics& K = s.sensor.K;
  j["sensor"] = {{"name", s.sensor.name},       {"width", K.width},         {"height", K.height},
                 {"fx", K.fx},                  {"fy", K.fy},               {"cx", K.cx},
                 {"cy", K.cy},                  {"min_range_mm", s.sensor.min_range_mm},
                 {"max_range_mm", s.sensor.max_range_mm}};
  const NoiseSettings& n = s.noise;
  j["noise"] = {
      {"model", n.model},
      {"gaussian", {{"sigma_mm", n.gaussian.sigma_mm}}},
      {"structured_light",
       {{"baseline_mm", n.structured_light.baseline_mm},
        {"disparity_step_px", n.structured_light.disparity_step_px},
        {"disparity_sigma_px", n.structured_light.disparity_sigma_px},
        {"smoothing_radius_px", n.structured_light.smoothing_radius_px},
        {"max_incidence_deg", n.structured_light.max_incidence_deg},
        {"shadows", n.structured_light.shadows}}},
      {"tof",
       {{"sigma_base_mm", n.tof.sigma_base_mm},
        {"sigma_per_m2_mm", n.tof.sigma_per_m2_mm},
        {"edge_jump_mm", n.tof.edge_jump_mm},
        {"flying_fraction", n.tof.flying_fraction},
        {"max_incidence_deg", n.tof.max_incidence_deg}}}};
  j["depth_scale"] = s.depth_scale;
  j["registry"] = s.registry.empty() ? "(default)" : s.registry;
  j["target"] = s.target;
  j["target_upright_probability"] = s.target_upright_probability;
  j["min_target_visib"] = s.min_target_visib;
  j["distractors"] = {{"pool", s.distractors.pool},
                      {"count", {s.distractors.min_count, s.distractors.max_count}},
                      {"upright_probability", s.distractors.upright_probability}};
  if (s.occlusion.enabled)
    j["occlusion"] = {{"visib_fract", range(s.occlusion.visib_fract)},
                      {"probability", s.occlusion.probability}};
  else
    j["occlusion"] = "none";
  j["camera"] = {{"distance_mm", range(s.camera.distance_mm)},
                 {"elevation_deg", range(s.camera.elevation_deg)},
                 {"look_jitter", s.camera.look_jitter}};
  if (s.scenario == Scenario::table)
    j["table"] = {{"size_mm", s.table.size_mm},
                  {"thickness_mm", s.table.thickness_mm},
                  {"gap_mm", s.table.gap_mm}};
  else
    j["warehouse"] = {{"object_size_mm", range(s.warehouse.object_size_mm)},
                      {"wall_distance_mm", range(s.warehouse.wall_distance_mm)},
                      {"wall_height_mm", s.warehouse.wall_height_mm},
                      {"gap_mm", s.warehouse.gap_mm}};
  j["masks"] = s.masks;
  j["max_attempts"] = s.max_attempts;
  return j.dump(2);
}

}  // namespace pb
