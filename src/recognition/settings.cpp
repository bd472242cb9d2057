// RecognitionSettings <-> YAML / JSON: assembles the stage sections, each
// parsed and serialized from its own field list.
#include "recognition/settings.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <type_traits>

#include "core/error.h"
#include "recognition/registry.h"

namespace pb {

const std::vector<std::string>& recognition_sections() {
  static const std::vector<std::string> v{"views", "preprocess", "local",  "global",
                                          "ppf",   "refine",     "verify", "scale"};
  return v;
}

namespace {

template <typename F>
void for_each_section(RecognitionSettings& s, F&& f) {
  f("views", s.views);
  f("preprocess", s.preprocess);
  f("local", s.local);
  f("global", s.global);
  f("ppf", s.ppf);
  f("refine", s.refine);
  f("verify", s.verify);
  f("scale", s.scale);
}

// Sets every relative field of a section to fraction x d (at least floor).
struct Resolver {
  const std::map<std::string, double>& relative;
  std::string prefix;
  double d = 0, floor = 0;
  template <typename T>
  void operator()(const char* key, T& v, const fields::Rule& = {}) {
    if constexpr (std::is_floating_point_v<T>) {
      const auto it = relative.find(prefix + key);
      if (it != relative.end()) v = std::max(it->second * d, floor);
    }
  }
  template <typename Sub>
  void section(const char* key, Sub& sub) {
    fields::nested(*this, key, sub);
  }
};

// Every length field's value in a default-constructed RecognitionSettings
// ("section.key" -> mm): the placeholder a relative field holds until it is
// resolved.
struct LengthCollector {
  std::map<std::string, double>& out;
  std::string prefix;
  template <typename T>
  void operator()(const char* key, const T& v, const fields::Rule& r = {}) {
    if constexpr (std::is_floating_point_v<T>)
      if (r.length) out[prefix + key] = v;
  }
  template <typename Sub>
  void section(const char* key, Sub& sub) {
    fields::nested(*this, key, sub);
  }
};
const std::map<std::string, double>& placeholders() {
  static const std::map<std::string, double> m = [] {
    std::map<std::string, double> out;
    RecognitionSettings d;
    for_each_section(d, [&](const char* name, auto& section) {
      LengthCollector c{out, std::string(name) + "."};
      std::decay_t<decltype(section)>::fields(section, c);
    });
    return out;
  }();
  return m;
}

// Sets the fields of `keys` to their placeholders, or (with `check`)
// compares every relative field with its placeholder.
struct PlaceholderVisitor {
  const std::map<std::string, double>& relative;
  const std::set<std::string>& keys;
  std::string prefix;
  bool check = false;
  template <typename T>
  void operator()(const char* key, T& v, const fields::Rule& = {}) {
    if constexpr (std::is_floating_point_v<T>) {
      const std::string k = prefix + key;
      if (!(check ? relative.count(k) : keys.count(k))) return;
      const double p = placeholders().at(k);
      if (!check) {
        v = p;
      } else if (v != p) {
        throw std::logic_error("settings: " + k + " was set to " + std::to_string(v) + " mm in code but is still "
                               "relative (" + fields::relative_text(relative.at(k)) + "); erase \"" + k +
                               "\" from RecognitionSettings::relative to use mm");
      }
    }
  }
  template <typename Sub>
  void section(const char* key, Sub& sub) {
    fields::nested(*this, key, sub);
  }
};

void visit_placeholders(RecognitionSettings& s, const std::set<std::string>& keys, bool check) {
  for_each_section(s, [&](const char* name, auto& section) {
    PlaceholderVisitor v{s.relative, keys, std::string(name) + ".", check};
    std::decay_t<decltype(section)>::fields(section, v);
  });
}

}  // namespace

RecognitionSettings parse_recognition_settings(const YamlNode& node, RecognitionSettings s,
                                               const std::set<std::string>& other_sections) {
  if (!node.defined()) return s;
  std::set<std::string> keys{"descriptor", "refinement", "seed"};
  keys.insert(recognition_sections().begin(), recognition_sections().end());
  keys.insert(other_sections.begin(), other_sections.end());
  node.check_keys(keys);
  if (node.has("descriptor")) s.descriptor = check_name(node["descriptor"], descriptor_names());
  if (node.has("refinement")) s.refinement = check_name(node["refinement"], refinement_names());
  std::set<std::string> given_relative;
  for_each_section(s, [&](const char* name, auto& section) {
    parse_section(node[name], section, &s.relative, std::string(name) + ".", &given_relative);
  });
  if (node.has("seed")) {
    const YamlNode n = node["seed"];
    const std::string text = n.as<std::string>();
    if (text.empty() || text[0] == '-') n.fail("must be a non-negative integer");
    s.seed = n.as<unsigned long long>();
  }
  visit_placeholders(s, given_relative, false);  // a base's mm value under a later "0.05d" is no number set in code
  return s;
}

nlohmann::ordered_json recognition_settings_json(const RecognitionSettings& settings) {
  RecognitionSettings s = settings;
  nlohmann::ordered_json j;
  j["descriptor"] = s.descriptor;
  j["refinement"] = s.refinement;
  for_each_section(s, [&](const char* name, const auto& section) {
    j[name] = section_json(section, &s.relative, std::string(name) + ".");
  });
  j["seed"] = s.seed;
  return j;
}

nlohmann::ordered_json recognition_settings_schema() {
  RecognitionSettings s;
  nlohmann::ordered_json j;
  j["descriptor"] = {{"type", "string"}, {"default", s.descriptor},
                     {"accepts", fields::rule_text(fields::one_of(descriptor_names()))}};
  j["refinement"] = {{"type", "string"}, {"default", s.refinement},
                     {"accepts", fields::rule_text(fields::one_of(refinement_names()))}};
  j["seed"] = {{"type", "integer"}, {"default", s.seed}, {"accepts", ">= 0"}};
  j["sections"] = nlohmann::ordered_json::array();
  for_each_section(s, [&](const char* name, const auto& section) {
    fields::SchemaWriter w;
    w.relative = &s.relative;
    w.prefix = std::string(name) + ".";
    std::decay_t<decltype(section)>::fields(section, w);
    j["sections"].push_back({{"name", name}, {"fields", std::move(w.fields)}});
    for (auto& sub : w.sections) {  // nested sections as "section.sub"
      sub["name"] = std::string(name) + "." + sub["name"].get<std::string>();
      j["sections"].push_back(std::move(sub));
    }
  });
  return j;
}

const std::map<std::string, double>& default_relative_lengths() {
  static const std::map<std::string, double> m{
      {"preprocess.voxel_mm", 0.05},           {"preprocess.plane_threshold_mm", 0.05},
      {"preprocess.normal_radius_mm", 0.10},   {"local.keypoint_voxel_mm", 0.075},
      {"local.descriptor_radius_mm", 0.30},    {"local.lrf_radius_mm", 0.20},
      {"local.hough_bin_mm", 0.25},            {"global.cluster_tolerance_mm", 0.06},
      {"global.cvfh_cluster_tolerance_mm", 0.075}, {"global.cvfh_normal_radius_mm", 0.10},
      {"ppf.position_cluster_mm", 0.15},       {"refine.max_correspondence_mm", 0.10},
      {"refine.ndt.resolution_mm", 0.15},      {"refine.ndt.step_size_mm", 0.40},
      {"verify.inlier_threshold_mm", 0.05},    {"verify.instance_separation_mm", 0.20},
  };
  return m;
}

RecognitionSettings resolve_lengths(const RecognitionSettings& in, double model_diameter_mm) {
  RecognitionSettings s = in;
  if (s.relative.empty()) return s;
  visit_placeholders(s, {}, true);
  const double d = s.scale.diameter_mm > 0 ? s.scale.diameter_mm : model_diameter_mm;
  if (!(d > 0) || !std::isfinite(d))
    throw InputError("settings", "scale.diameter_mm",
                     "'" + s.relative.begin()->first + "' is relative to the object's diameter, which is unknown "
                     "here: give scale.diameter_mm or the length in mm");
  for_each_section(s, [&](const char* name, auto& section) {
    Resolver r{s.relative, std::string(name) + ".", d * s.scale.length_factor, s.scale.min_length_mm};
    std::decay_t<decltype(section)>::fields(section, r);
  });
  if (s.relative.count("verify.inlier_threshold_mm") && s.verify.inlier_threshold_max_voxels > 0)
    s.verify.inlier_threshold_mm =
        std::max(s.scale.min_length_mm,
                 std::min(s.verify.inlier_threshold_mm, s.verify.inlier_threshold_max_voxels * s.preprocess.voxel_mm));
  s.relative.clear();
  return s;
}

double depth_noise_sigma_mm(const DepthImage& image) {
  double sum = 0;
  size_t n = 0;
  const auto valid = [](float z) { return z > 0 && std::isfinite(z); };
  if (image.width < 3 || image.height < 1 ||
      image.z.size() < static_cast<size_t>(image.width) * static_cast<size_t>(image.height))
    return 0;
  for (int v = 0; v < image.height; ++v) {
    const float* row = image.z.data() + static_cast<size_t>(v) * static_cast<size_t>(image.width);
    for (int u = 1; u + 1 < image.width; ++u) {
      if (!valid(row[u - 1]) || !valid(row[u]) || !valid(row[u + 1])) continue;
      const double d = static_cast<double>(row[u - 1]) - 2.0 * row[u] + row[u + 1];
      if (std::abs(d) > 0.02 * row[u]) continue;
      sum += d * d;
      ++n;
    }
  }
  return n > 0 ? std::sqrt(sum / static_cast<double>(n) / 6.0) : 0.0;
}

double sensor_length_floor_mm(const ScaleSettings& scale, const DepthImage& image, const Intrinsics& K) {
  const double noise = scale.sensor_floor_sigmas > 0 ? scale.sensor_floor_sigmas * depth_noise_sigma_mm(image) : 0;
  if (!(scale.sensor_floor_px > 0) || !(K.fx > 0)) return noise;
  double z = scale.working_distance_mm;
  if (!(z > 0)) {
    std::vector<float> valid;
    valid.reserve(image.z.size());
    for (const float v : image.z)
      if (v > 0 && std::isfinite(v)) valid.push_back(v);
    if (valid.empty()) return noise;
    std::nth_element(valid.begin(), valid.begin() + static_cast<std::ptrdiff_t>(valid.size() / 2), valid.end());
    z = valid[valid.size() / 2];
  }
  return std::max(noise, scale.sensor_floor_px * z / K.fx);
}

bool needs_sensor_floor(const RecognitionSettings& s) {
  return !s.relative.empty() && !(s.scale.min_length_mm > 0);
}

RecognitionSettings resolve_for_scene(const RecognitionSettings& s, double model_diameter_mm, const DepthImage& first,
                                      const Intrinsics& first_K) {
  return resolve_for_scene(s, model_diameter_mm,
                           needs_sensor_floor(s) ? sensor_length_floor_mm(s.scale, first, first_K) : 0.0);
}

RecognitionSettings resolve_for_scene(const RecognitionSettings& in, double model_diameter_mm, double sensor_floor_mm) {
  RecognitionSettings s = in;
  if (needs_sensor_floor(s)) s.scale.min_length_mm = sensor_floor_mm;
  return resolve_lengths(s, model_diameter_mm);
}

std::string settings_to_json(const RecognitionSettings& s) { return recognition_settings_json(s).dump(); }

RecognitionSettings apply_setting(const RecognitionSettings& s, const std::string& path, const YamlNode& value) {
  // {section: {key: value}} around the config's own node, so that errors
  // name its file and line.
  YAML::Node root(YAML::NodeType::Map);
  YAML::Node at = root;
  size_t start = 0;
  for (size_t dot = path.find('.'); dot != std::string::npos; start = dot + 1, dot = path.find('.', start)) {
    YAML::Node next(YAML::NodeType::Map);
    at[path.substr(start, dot - start)] = next;
    at.reset(next);
  }
  at[path.substr(start)] = value.raw();
  return parse_recognition_settings(YamlNode(root, value.file()), s);
}

namespace {

// The entries of `j` that differ from `base`, objects compared key by key.
nlohmann::ordered_json changes(const nlohmann::ordered_json& j, const nlohmann::ordered_json& base) {
  nlohmann::ordered_json out = nlohmann::ordered_json::object();
  for (auto it = j.begin(); it != j.end(); ++it) {
    const auto b = base.find(it.key());
    if (b == base.end() || !it.value().is_object() || !b->is_object()) {
      if (b == base.end() || *b != it.value()) out[it.key()] = it.value();
      continue;
    }
    nlohmann::ordered_json sub = changes(it.value(), *b);
    if (!sub.empty()) out[it.key()] = std::move(sub);
  }
  return out;
}

}  // namespace

nlohmann::ordered_json settings_changes_json(const RecognitionSettings& s) {
  const nlohmann::ordered_json all = recognition_settings_json(s);
  nlohmann::ordered_json out = {{"descriptor", s.descriptor}, {"refinement", s.refinement}};
  static const nlohmann::ordered_json defaults = recognition_settings_json(RecognitionSettings{});
  out.update(changes(all, defaults));
  return out;
}

}  // namespace pb
