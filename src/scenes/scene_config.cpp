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
    st.occlusion.box_depth_mm = {300, 800};
    st.occlusion.cylinder_min_radius_mm = 150;
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

double read_at_most(const YamlNode& parent, const std::string& key, double fallback, double min_value,
                    double max_value) {
  const double v = parent.get_or<double>(key, fallback);
  if (!std::isfinite(v)) parent[key].fail("must be finite");
  if (!(v >= min_value)) parent[key].fail("must be at least " + num(min_value) + ", got " + num(v));
  if (!(v <= max_value)) parent[key].fail("must be at most " + num(max_value) + ", got " + num(v));
  return v;
}

void parse_camera(const YamlNode& c, SceneCameraSettings& cam) {
  c.check_keys({"distance_mm", "elevation_deg", "look_jitter", "near_mm", "far_mm", "clearance_mm",
                "depth_clearance_mm"});
  read_range(c, "distance_mm", cam.distance_mm, true);
  read_range(c, "elevation_deg", cam.elevation_deg, false, -89.0, 89.0);
  cam.look_jitter = c.get_nonnegative("look_jitter", cam.look_jitter);
  if (cam.look_jitter > 1.0) c["look_jitter"].fail("must be at most 1");
  cam.near_mm = c.get_positive("near_mm", cam.near_mm);
  cam.far_mm = c.get_positive("far_mm", cam.far_mm);
  if (!(cam.far_mm > cam.near_mm)) c[c.has("far_mm") ? "far_mm" : "near_mm"].fail("need near_mm < far_mm");
  cam.clearance_mm = c.get_nonnegative("clearance_mm", cam.clearance_mm);
  cam.depth_clearance_mm = c.get_nonnegative("depth_clearance_mm", cam.depth_clearance_mm);
}

void parse_distractors(const YamlNode& d, DistractorSettings& ds) {
  d.check_keys({"pool", "count", "upright_probability", "placement_tries", "spread_min_radii", "spread_max_radii",
                "image_margin"});
  if (d.has("pool")) ds.pool = d.get<std::vector<std::string>>("pool");
  if (d.has("count")) {
    ValueRange r{double(ds.min_count), double(ds.max_count)};
    read_range(d, "count", r, false, 0.0, 100.0);
    if (r.lo != std::floor(r.lo) || r.hi != std::floor(r.hi)) d["count"].fail("must be whole numbers");
    ds.min_count = static_cast<int>(r.lo);
    ds.max_count = static_cast<int>(r.hi);
  }
  ds.upright_probability = read_probability(d, "upright_probability", ds.upright_probability);
  ds.placement_tries = read_int_at_least(d, "placement_tries", ds.placement_tries, 1);
  ds.spread_min_radii = d.get_nonnegative("spread_min_radii", ds.spread_min_radii);
  ds.spread_max_radii = d.get_nonnegative("spread_max_radii", ds.spread_max_radii);
  if (ds.spread_max_radii > 0 && ds.spread_max_radii < ds.spread_min_radii)
    d[d.has("spread_max_radii") ? "spread_max_radii" : "spread_min_radii"].fail(
        "need spread_max_radii 0 (no cap) or at least spread_min_radii");
  ds.image_margin = read_at_most(d, "image_margin", ds.image_margin, 0.0, 10.0);
}

// The map form of occlusion: {visib_fract, probability, layout details}.
void parse_occlusion_map(const YamlNode& o, OcclusionSettings& oc) {
  o.check_keys({"visib_fract", "probability", "box_probability", "box_width", "box_depth_mm",
                "cylinder_radius", "cylinder_min_radius_mm", "lateral_offset", "extra_distance",
                "height_factor", "height_margin_mm", "camera_headroom_mm", "min_height_mm", "token_height",
                "search_iterations", "search_tolerance", "footprint_sides", "cylinder_segments"});
  oc.enabled = true;
  read_range(o, "visib_fract", oc.visib_fract, false, 0.0, 1.0);
  oc.probability = read_probability(o, "probability", oc.probability);
  oc.box_probability = read_probability(o, "box_probability", oc.box_probability);
  read_range(o, "box_width", oc.box_width, true);
  read_range(o, "box_depth_mm", oc.box_depth_mm, true);
  read_range(o, "cylinder_radius", oc.cylinder_radius, true);
  oc.cylinder_min_radius_mm = o.get_nonnegative("cylinder_min_radius_mm", oc.cylinder_min_radius_mm);
  read_range(o, "lateral_offset", oc.lateral_offset, false, -100.0, 100.0);
  read_range(o, "extra_distance", oc.extra_distance, false, 0.0, 100.0);
  oc.height_factor = o.get_positive("height_factor", oc.height_factor);
  oc.height_margin_mm = o.get_nonnegative("height_margin_mm", oc.height_margin_mm);
  oc.camera_headroom_mm = o.get_nonnegative("camera_headroom_mm", oc.camera_headroom_mm);
  oc.min_height_mm = o.get_nonnegative("min_height_mm", oc.min_height_mm);
  oc.token_height = read_at_most(o, "token_height", oc.token_height, 0.0, 1.0);
  oc.search_iterations = read_int_at_least(o, "search_iterations", oc.search_iterations, 0);
  oc.search_tolerance = read_at_most(o, "search_tolerance", oc.search_tolerance, 0.0, 1.0);
  oc.footprint_sides = read_int_at_least(o, "footprint_sides", oc.footprint_sides, 3);
  oc.cylinder_segments = read_int_at_least(o, "cylinder_segments", oc.cylinder_segments, 3);
}

void parse_occlusion(const YamlNode& root, OcclusionSettings& oc) {
  const YamlNode o = root["occlusion"];
  if (o.is_scalar()) {
    const std::string v = o.as<std::string>();
    if (v != "none") o.fail("expected none, a range [lo, hi] or {visib_fract, probability}");
    oc.enabled = false;
  } else if (o.is_sequence()) {
    oc.enabled = true;
    read_range(root, "occlusion", oc.visib_fract, false, 0.0, 1.0);
  } else {
    parse_occlusion_map(o, oc);
  }
}

void parse_table(const YamlNode& t, TableSettings& ts) {
  t.check_keys({"size_mm", "thickness_mm", "gap_mm", "floor_drop_mm", "wall_distance_mm"});
  ts.size_mm = t.get_positive("size_mm", ts.size_mm);
  ts.thickness_mm = t.get_positive("thickness_mm", ts.thickness_mm);
  ts.gap_mm = t.get_nonnegative("gap_mm", ts.gap_mm);
  ts.floor_drop_mm = t.get_nonnegative("floor_drop_mm", ts.floor_drop_mm);
  if (ts.floor_drop_mm > 0 && ts.floor_drop_mm < ts.thickness_mm)
    t["floor_drop_mm"].fail("must be 0 (no floor) or at least the table's thickness_mm (" + num(ts.thickness_mm) + ")");
  read_range(t, "wall_distance_mm", ts.wall_distance_mm, false);
}

void parse_warehouse(const YamlNode& w, WarehouseSettings& ws) {
  w.check_keys({"object_size_mm", "wall_distance_mm", "wall_height_mm", "gap_mm", "wall_yaw_deg",
                "wall_thickness_mm", "wall_length_mm", "floor_size_mm", "floor_thickness_mm", "wall"});
  if (w.has("wall")) ws.wall = w["wall"].as<bool>();
  read_range(w, "object_size_mm", ws.object_size_mm, true);
  read_range(w, "wall_distance_mm", ws.wall_distance_mm, true);
  ws.wall_height_mm = w.get_positive("wall_height_mm", ws.wall_height_mm);
  ws.gap_mm = w.get_nonnegative("gap_mm", ws.gap_mm);
  ws.wall_yaw_deg = read_at_most(w, "wall_yaw_deg", ws.wall_yaw_deg, 0.0, 89.0);
  ws.wall_thickness_mm = w.get_positive("wall_thickness_mm", ws.wall_thickness_mm);
  ws.wall_length_mm = w.get_positive("wall_length_mm", ws.wall_length_mm);
  ws.floor_size_mm = w.get_positive("floor_size_mm", ws.floor_size_mm);
  ws.floor_thickness_mm = w.get_positive("floor_thickness_mm", ws.floor_thickness_mm);
}

// Top-level keys up to the sensor and noise.
void parse_identity_and_sensor(const YamlNode& root, SceneSettings& s) {
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
  if (root.has("stated_intrinsics")) {
    const YamlNode st = root["stated_intrinsics"];
    st.check_keys({"width", "height", "fx", "fy", "cx", "cy", "hfov_deg", "vfov_deg"});
    s.stated_intrinsics = parse_intrinsics(st, s.sensor.K);
    if (s.stated_intrinsics.width != s.sensor.K.width || s.stated_intrinsics.height != s.sensor.K.height)
      st.fail("must keep the sensor's image size (" + std::to_string(s.sensor.K.width) + " x " +
              std::to_string(s.sensor.K.height) + ")");
    s.has_stated_intrinsics = true;
  }
}

}  // namespace

SceneSettings parse_scene_settings(const YamlNode& root) {
  root.check_keys({"scenario", "description", "scene_id", "seed", "images", "sensor", "noise",
                   "depth_scale", "stated_intrinsics", "registry", "target", "target_upright_probability",
                   "target_free_probability",
                   "target_tilt_deg", "min_target_visib", "distractors", "occlusion", "camera", "table", "warehouse",
                   "setups", "masks", "max_attempts"});
  const std::string scen = root.get<std::string>("scenario");
  Scenario scenario;
  if (scen == "table") scenario = Scenario::table;
  else if (scen == "warehouse") scenario = Scenario::warehouse;
  else root["scenario"].fail("unknown scenario '" + scen + "' (table | warehouse)");

  SceneSettings s = default_scene_settings(scenario);
  parse_identity_and_sensor(root, s);
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
  s.target_free_probability = read_probability(root, "target_free_probability", s.target_free_probability);
  s.target_tilt_deg = root.get_or<double>("target_tilt_deg", s.target_tilt_deg);
  if (!(s.target_tilt_deg >= 0.0 && s.target_tilt_deg <= 90.0))
    root["target_tilt_deg"].fail("must be in [0, 90] degrees, got " + num(s.target_tilt_deg));
  s.min_target_visib = read_probability(root, "min_target_visib", s.min_target_visib);

  if (root.has("distractors")) parse_distractors(root["distractors"], s.distractors);
  if (s.distractors.max_count > 0 && s.distractors.pool.empty())
    root["distractors"].fail("count > 0 needs a non-empty pool");
  if (root.has("occlusion")) parse_occlusion(root, s.occlusion);
  if (root.has("camera")) parse_camera(root["camera"], s.camera);
  if (root.has("table")) parse_table(root["table"], s.table);
  if (root.has("warehouse")) parse_warehouse(root["warehouse"], s.warehouse);
  s.setups = read_int_at_least(root, "setups", s.setups, 0);
  if (s.setups > s.images) root["setups"].fail("must be at most images (" + std::to_string(s.images) + ")");
  if (s.setups > 0 && s.occlusion.enabled)
    root["setups"].fail("not with occlusion (its occluder stands on each camera's line of sight)");
  if (s.setups > 0 && ((s.scenario == Scenario::warehouse && s.warehouse.wall) || s.table.wall_distance_mm.hi > 0))
    root["setups"].fail("not with a wall (it stands behind the target as one camera sees it)");
  root.read("masks", s.masks);
  s.max_attempts = read_int_at_least(root, "max_attempts", s.max_attempts, 1);
  return s;
}

SceneSettings load_scene_settings(const std::string& path) {
  return parse_scene_settings(YamlNode::load_file(path));
}

namespace {

using nlohmann::ordered_json;

ordered_json range_json(const ValueRange& r) { return ordered_json::array({r.lo, r.hi}); }

// The layout details of a scenario's sections, each listed once.
ordered_json layout_details(const SceneSettings& s) {
  const SceneCameraSettings& c = s.camera;
  const DistractorSettings& d = s.distractors;
  const OcclusionSettings& o = s.occlusion;
  const WarehouseSettings& w = s.warehouse;
  ordered_json j;
  j["camera"] = {{"near_mm", c.near_mm}, {"far_mm", c.far_mm}, {"clearance_mm", c.clearance_mm},
                 {"depth_clearance_mm", c.depth_clearance_mm}};
  j["distractors"] = {{"placement_tries", d.placement_tries}, {"spread_min_radii", d.spread_min_radii},
                      {"spread_max_radii", d.spread_max_radii}, {"image_margin", d.image_margin}};
  if (o.enabled)
    j["occlusion"] = {
        {"box_probability", o.box_probability},   {"box_width", range_json(o.box_width)},
        {"box_depth_mm", range_json(o.box_depth_mm)}, {"cylinder_radius", range_json(o.cylinder_radius)},
        {"cylinder_min_radius_mm", o.cylinder_min_radius_mm}, {"lateral_offset", range_json(o.lateral_offset)},
        {"extra_distance", range_json(o.extra_distance)}, {"height_factor", o.height_factor},
        {"height_margin_mm", o.height_margin_mm}, {"camera_headroom_mm", o.camera_headroom_mm},
        {"min_height_mm", o.min_height_mm},       {"token_height", o.token_height},
        {"search_iterations", o.search_iterations}, {"search_tolerance", o.search_tolerance},
        {"footprint_sides", o.footprint_sides},   {"cylinder_segments", o.cylinder_segments}};
  if (s.scenario == Scenario::table)
    j["table"] = {{"floor_drop_mm", s.table.floor_drop_mm}, {"wall_distance_mm", range_json(s.table.wall_distance_mm)}};
  if (s.scenario == Scenario::warehouse)
    j["warehouse"] = {{"wall_yaw_deg", w.wall_yaw_deg}, {"wall_thickness_mm", w.wall_thickness_mm},
                      {"wall_length_mm", w.wall_length_mm}, {"floor_size_mm", w.floor_size_mm},
                      {"floor_thickness_mm", w.floor_thickness_mm}, {"wall", w.wall}};
  return j;
}

// Adds the layout details that differ from their defaults to their sections
// of `j`, so that posebench_scene.json of a scene set made with the defaults
// keeps its bytes.
void add_layout_details(ordered_json& j, const SceneSettings& s) {
  SceneSettings defaults = default_scene_settings(s.scenario);
  defaults.occlusion.enabled = s.occlusion.enabled;
  const ordered_json mine = layout_details(s), def = layout_details(defaults);
  for (auto section = mine.begin(); section != mine.end(); ++section)
    for (auto it = section.value().begin(); it != section.value().end(); ++it)
      if (it.value() != def[section.key()][it.key()]) j[section.key()][it.key()] = it.value();
}

}  // namespace

std::string scene_settings_json(const SceneSettings& s) {
  auto range = range_json;
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
      {"tof", tof_json(n.tof)}};
  j["depth_scale"] = s.depth_scale;
  if (s.has_stated_intrinsics) {  // older sets' json
    const Intrinsics& S = s.stated_intrinsics;
    j["stated_intrinsics"] = {{"fx", S.fx}, {"fy", S.fy}, {"cx", S.cx}, {"cy", S.cy}};
  }
  j["registry"] = s.registry.empty() ? "(default)" : s.registry;
  j["target"] = s.target;
  j["target_upright_probability"] = s.target_upright_probability;
  if (s.target_free_probability > 0) j["target_free_probability"] = s.target_free_probability;  // older sets' json
  if (s.target_tilt_deg > 0) j["target_tilt_deg"] = s.target_tilt_deg;  // older sets' json
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
  add_layout_details(j, s);
  if (s.setups > 0) j["setups"] = s.setups;  // older sets' json
  j["masks"] = s.masks;
  j["max_attempts"] = s.max_attempts;
  return j.dump(2);
}

const Intrinsics& dataset_intrinsics(const SceneSettings& s) {
  return s.has_stated_intrinsics ? s.stated_intrinsics : s.sensor.K;
}

Pose stated_pose(const Pose& T_cam_model, const Intrinsics& K, const Intrinsics& stated) {
  Pose T = T_cam_model;
  T.t = stated.K().inverse() * (K.K() * T_cam_model.t);
  return T;
}

}  // namespace pb
