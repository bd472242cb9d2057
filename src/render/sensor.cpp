// Sensor profiles: the built-in sensors and their YAML (see sensor.h);
// the noise models are applied in sensor_noise.cpp.
#include "render/sensor.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>

#include "core/error.h"

namespace pb {

namespace {

void check_intrinsics(const YamlNode& node, const Intrinsics& K) {
  if (K.width < 1 || K.width > 16384) node["width"].fail("must be 1..16384");
  if (K.height < 1 || K.height > 16384) node["height"].fail("must be 1..16384");
  if (!(K.fx > 0) || !std::isfinite(K.fx)) node[node.has("fx") ? "fx" : "hfov_deg"].fail("must be positive");
  if (!(K.fy > 0) || !std::isfinite(K.fy)) node[node.has("fy") ? "fy" : "vfov_deg"].fail("must be positive");
  if (!std::isfinite(K.cx)) node["cx"].fail("must be finite");
  if (!std::isfinite(K.cy)) node["cy"].fail("must be finite");
}

double fov_deg(const YamlNode& node, const std::string& key) {
  const double v = node.get<double>(key);
  if (!(v > 0 && v < 180)) node[key].fail("must be in (0, 180) degrees");
  return v;
}

bool is_builtin(const std::string& name) {
  const auto names = sensor_names();
  return std::find(names.begin(), names.end(), name) != names.end();
}

// A profile file named in a YAML file: relative to that file's folder,
// else to the working directory; InputError naming the field when missing.
std::string resolve_beside(const std::string& name, const YamlNode& node) {
  namespace fs = std::filesystem;
  if (fs::path(name).is_relative() && !node.file().empty()) {
    const fs::path beside = fs::path(node.file()).parent_path() / name;
    if (fs::exists(beside)) return beside.string();
  }
  if (!fs::exists(name)) node.fail("sensor profile file '" + name + "' does not exist");
  return name;
}

std::string unknown_sensor(const std::string& name) {
  std::string list;
  for (const auto& n : sensor_names()) list += (list.empty() ? "" : ", ") + n;
  return "unknown sensor '" + name + "' (built in: " + list +
         "; or give a map with width, height, fx, fy, cx, cy, or a profile file NAME.yaml)";
}

// The structured-light model's fields, in noise_json's order.
nlohmann::ordered_json structured_light_json(const StructuredLightNoise& s) {
  return {{"baseline_mm", s.baseline_mm},
          {"disparity_step_px", s.disparity_step_px},
          {"disparity_sigma_px", s.disparity_sigma_px},
          {"smoothing_radius_px", s.smoothing_radius_px},
          {"smoothing_edge_px", s.smoothing_edge_px},
          {"max_incidence_deg", s.max_incidence_deg},
          {"shadows", s.shadows},
          {"edge_bleed_px", s.edge_bleed_px},
          {"edge_dropout_rate", s.edge_dropout_rate},
          {"edge_dropout_px", s.edge_dropout_px},
          {"reference_fx", s.reference_fx}};
}

std::set<std::string> keys_of(const nlohmann::ordered_json& object) {
  std::set<std::string> keys;
  for (auto it = object.begin(); it != object.end(); ++it) keys.insert(it.key());
  return keys;
}

}  // namespace

std::vector<std::string> sensor_names() { return {"synthetic", "astra", "kinect_one"}; }

SensorProfile sensor_profile(const std::string& name, const std::string& file, const std::string& field) {
  SensorProfile s;
  s.name = name;
  if (name == "synthetic") {
    // Ideal rasterized sensor of the thesis's synthetic images.
    s.K = Intrinsics::from_fov(512, 512, 30, 30);
    s.depth_scale = 0.2;  // uint16 holds up to 13.1 m (warehouse walls)
    s.min_range_mm = 100;
    s.max_range_mm = 13000;
    s.noise.model = "gaussian";
  } else if (name == "astra") {
    // Structured light, 0.4 to 8 m.
    s.K = Intrinsics::from_fov(640, 480, 59, 46);
    s.depth_scale = 0.125;  // uint16 holds up to 8.19 m
    s.min_range_mm = 400;
    s.max_range_mm = 8000;
    s.noise.model = "structured_light";
  } else if (name == "kinect_one") {
    // Time of flight, 0.5 to 4.5 m.
    s.K = Intrinsics::from_fov(512, 424, 57, 43);
    s.depth_scale = 0.1;
    s.min_range_mm = 500;
    s.max_range_mm = 4500;
    s.noise.model = "tof";
  } else {
    throw InputError(file, field, unknown_sensor(name));
  }
  return s;
}

Intrinsics parse_intrinsics(const YamlNode& node, const Intrinsics& base) {
  Intrinsics K = base;
  K.width = base.width > 0 ? node.get_or<int>("width", base.width) : node.get<int>("width");
  K.height = base.height > 0 ? node.get_or<int>("height", base.height) : node.get<int>("height");
  if (K.width < 1 || K.width > 16384) node["width"].fail("must be 1..16384");
  if (K.height < 1 || K.height > 16384) node["height"].fail("must be 1..16384");
  const bool focal = node.has("fx") || node.has("fy");
  const bool fov = node.has("hfov_deg") || node.has("vfov_deg");
  if (focal && fov) node.fail("give either fx, fy or hfov_deg, vfov_deg, not both");
  if (fov) {
    K = Intrinsics::from_fov(K.width, K.height, fov_deg(node, "hfov_deg"), fov_deg(node, "vfov_deg"));
  } else {
    K.fx = base.fx > 0 ? node.get_or<double>("fx", base.fx) : node.get<double>("fx");
    K.fy = base.fy > 0 ? node.get_or<double>("fy", base.fy) : node.get<double>("fy");
  }
  // The principal point: given, else the base's for an image of its size,
  // else the image centre.
  const bool same_size = K.width == base.width && K.height == base.height;
  K.cx = node.get_or<double>("cx", same_size ? base.cx : 0.5 * (K.width - 1));
  K.cy = node.get_or<double>("cy", same_size ? base.cy : 0.5 * (K.height - 1));
  check_intrinsics(node, K);
  return K;
}

SensorProfile parse_sensor(const YamlNode& node) {
  if (!node.defined()) node.fail("missing sensor (a name or a map of intrinsics)");
  if (node.is_scalar()) {
    const std::string name = node.as<std::string>();
    if (is_profile_file(name)) {
      const YamlNode file = YamlNode::load_file(resolve_beside(name, node));
      if (file.is_scalar()) file.fail("a sensor profile file holds a map (name, intrinsics, noise)");
      return parse_sensor(file);
    }
    if (!is_builtin(name)) node.fail(unknown_sensor(name));  // names file, field and line
    return sensor_profile(name, node.file(), node.path());
  }
  node.check_keys({"name", "width", "height", "fx", "fy", "cx", "cy", "hfov_deg", "vfov_deg", "depth_scale",
                   "min_range_mm", "max_range_mm", "noise"});
  const bool has_intrinsics = node.has("width") || node.has("height") || node.has("fx") || node.has("fy") ||
                              node.has("cx") || node.has("cy") || node.has("hfov_deg") || node.has("vfov_deg");
  SensorProfile s;
  const std::string name = node.get_or<std::string>("name", "custom");
  if (is_builtin(name)) {
    // A built-in profile, with other optics or ranges where the map gives them.
    s = sensor_profile(name, node.file(), node["name"].path());
    if (has_intrinsics) s.K = parse_intrinsics(node, s.K);
  } else {
    if (!has_intrinsics) node["name"].fail(unknown_sensor(name));
    s.name = name;
    s.noise.model = "gaussian";
    s.min_range_mm = 100;
    s.max_range_mm = 6500;
    s.depth_scale = 0.1;
    s.K = parse_intrinsics(node, Intrinsics{});
  }
  s.depth_scale = node.get_positive("depth_scale", s.depth_scale);
  s.min_range_mm = node.get_nonnegative("min_range_mm", s.min_range_mm);
  s.max_range_mm = node.get_positive("max_range_mm", s.max_range_mm);
  if (!(s.max_range_mm > s.min_range_mm))
    node["max_range_mm"].fail("must be larger than min_range_mm (" + std::to_string(s.min_range_mm) + ")");
  if (s.max_range_mm > 65535.0 * s.depth_scale)
    node[node.has("max_range_mm") ? "max_range_mm" : "depth_scale"].fail(
        "max_range_mm " + std::to_string(s.max_range_mm) + " does not fit a uint16 depth PNG with depth_scale " +
        std::to_string(s.depth_scale) + " (limit 65535 * depth_scale)");
  if (node.has("noise")) s.noise = parse_noise(node["noise"], s.noise);
  return s;
}

bool is_profile_file(const std::string& name) {
  const auto ends = [&](const std::string& ext) {
    return name.size() > ext.size() && name.compare(name.size() - ext.size(), ext.size(), ext) == 0;
  };
  return ends(".yaml") || ends(".yml");
}

NoiseSettings parse_noise(const YamlNode& node, const NoiseSettings& base) {
  NoiseSettings n = base;
  if (!node.defined()) return n;
  const std::set<std::string> models = {"none", "gaussian", "structured_light", "tof"};
  auto check_model = [&](const YamlNode& at, const std::string& m) {
    if (!models.count(m))
      at.fail("unknown noise model '" + m + "' (none, gaussian, structured_light, tof)");
  };
  if (node.is_scalar()) {
    n.model = node.as<std::string>();
    check_model(node, n.model);
    return n;
  }
  const std::set<std::string> gaussian_keys = {"sigma_mm"};
  // Each model's keys: those noise_json writes for it.
  const std::set<std::string> sl_keys = keys_of(structured_light_json(StructuredLightNoise{}));
  const std::set<std::string> tof_keys = keys_of(tof_json(TimeOfFlightNoise{}));
  std::set<std::string> all = {"model"};
  all.insert(gaussian_keys.begin(), gaussian_keys.end());
  all.insert(sl_keys.begin(), sl_keys.end());
  all.insert(tof_keys.begin(), tof_keys.end());
  node.check_keys(all);
  n.model = node.get_or<std::string>("model", base.model);
  check_model(node["model"], n.model);
  const std::set<std::string>* own = nullptr;
  if (n.model == "gaussian") own = &gaussian_keys;
  if (n.model == "structured_light") own = &sl_keys;
  if (n.model == "tof") own = &tof_keys;
  for (const std::string& k : node.keys())
    if (k != "model" && (!own || !own->count(k)))
      node[k].fail("does not apply to noise model '" + n.model + "'");

  auto incidence = [&](double fallback) {
    const double v = node.get_or<double>("max_incidence_deg", fallback);
    if (!(v > 0 && v <= 90)) node["max_incidence_deg"].fail("must be in (0, 90] degrees");
    return v;
  };
  if (n.model == "gaussian") {
    n.gaussian.sigma_mm = node.get_nonnegative("sigma_mm", n.gaussian.sigma_mm);
  } else if (n.model == "structured_light") {
    StructuredLightNoise& s = n.structured_light;
    s.baseline_mm = node.get_positive("baseline_mm", s.baseline_mm);
    s.disparity_step_px = node.get_positive("disparity_step_px", s.disparity_step_px);
    s.disparity_sigma_px = node.get_nonnegative("disparity_sigma_px", s.disparity_sigma_px);
    s.smoothing_radius_px = node.get_or<int>("smoothing_radius_px", s.smoothing_radius_px);
    if (s.smoothing_radius_px < 0 || s.smoothing_radius_px > 10)
      node["smoothing_radius_px"].fail("must be 0..10");
    s.smoothing_edge_px = node.get_nonnegative("smoothing_edge_px", s.smoothing_edge_px);
    s.max_incidence_deg = incidence(s.max_incidence_deg);
    node.read("shadows", s.shadows);
    s.edge_bleed_px = node.get_nonnegative("edge_bleed_px", s.edge_bleed_px);
    if (s.edge_bleed_px > 10) node["edge_bleed_px"].fail("must be 0..10");
    s.edge_dropout_rate = node.get_nonnegative("edge_dropout_rate", s.edge_dropout_rate);
    if (s.edge_dropout_rate > 1) node["edge_dropout_rate"].fail("must be in [0, 1]");
    s.edge_dropout_px = node.get_positive("edge_dropout_px", s.edge_dropout_px);
    if (s.edge_dropout_px > 50) node["edge_dropout_px"].fail("must be in (0, 50]");
    s.reference_fx = node.get_nonnegative("reference_fx", s.reference_fx);
  } else if (n.model == "tof") {
    TimeOfFlightNoise& t = n.tof;
    t.sigma_base_mm = node.get_nonnegative("sigma_base_mm", t.sigma_base_mm);
    t.sigma_per_m2_mm = node.get_nonnegative("sigma_per_m2_mm", t.sigma_per_m2_mm);
    t.edge_jump_mm = node.get_positive("edge_jump_mm", t.edge_jump_mm);
    t.flying_fraction = node.get_nonnegative("flying_fraction", t.flying_fraction);
    if (t.flying_fraction > 1) node["flying_fraction"].fail("must be in [0, 1]");
    t.max_incidence_deg = incidence(t.max_incidence_deg);
    node.read("driver_edge_filter", t.driver_edge_filter);
    t.edge_filter_close_mm = node.get_nonnegative("edge_filter_close_mm", t.edge_filter_close_mm);
    t.edge_filter_far_mm = node.get_nonnegative("edge_filter_far_mm", t.edge_filter_far_mm);
    t.edge_filter_span_mm = node.get_nonnegative("edge_filter_span_mm", t.edge_filter_span_mm);
  }
  return n;
}

nlohmann::ordered_json noise_json(const NoiseSettings& n) {
  nlohmann::ordered_json j;
  j["model"] = n.model;
  if (n.model == "gaussian") j["sigma_mm"] = n.gaussian.sigma_mm;
  if (n.model == "structured_light") j.update(structured_light_json(n.structured_light));
  if (n.model == "tof") j.update(tof_json(n.tof));
  return j;
}

nlohmann::ordered_json tof_json(const TimeOfFlightNoise& t) {
  return {{"sigma_base_mm", t.sigma_base_mm},
          {"sigma_per_m2_mm", t.sigma_per_m2_mm},
          {"edge_jump_mm", t.edge_jump_mm},
          {"flying_fraction", t.flying_fraction},
          {"max_incidence_deg", t.max_incidence_deg},
          {"driver_edge_filter", t.driver_edge_filter},
          {"edge_filter_close_mm", t.edge_filter_close_mm},
          {"edge_filter_far_mm", t.edge_filter_far_mm},
          {"edge_filter_span_mm", t.edge_filter_span_mm}};
}

}  // namespace pb
