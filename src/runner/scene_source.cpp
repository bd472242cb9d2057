// The `scenes:` entries of an experiment: a scene config to generate, a BOP
// dataset (real or generated), point clouds to import, or the twin of
// another entry (experiment.h SceneSource).
#include <algorithm>
#include <cstdlib>
#include <filesystem>

#include "io/cloud.h"
#include "recognition/pipeline.h"
#include "recognition/registry.h"
#include "render/sensor.h"
#include "runner/experiment_internal.h"

namespace pb::experiment_detail {

namespace fs = std::filesystem;

std::string resolve(const std::string& base_file, const std::string& p) {
  if (p.empty() || fs::path(p).is_absolute()) return p;
  // Paths are relative to the current directory when they exist there (the
  // usual case: run from the project root), else to the config's folder.
  std::error_code ec;  // a path the OS rejects (a name too long) is not there, not an exception
  if (fs::exists(p, ec)) return p;
  return (fs::path(base_file).parent_path() / p).string();
}

void check_refinements(const YamlNode& node, const std::vector<std::string>& names) {
  const auto known = refinement_names();
  for (const auto& r : names)
    if (std::find(known.begin(), known.end(), r) == known.end()) node.fail("unknown refinement '" + r + "'");
}

namespace {

// ${NAME} in a path: the environment variable's value; InputError naming
// the field when it is not set.
std::string expand_env(const YamlNode& node, std::string p) {
  for (size_t a; (a = p.find("${")) != std::string::npos;) {
    const size_t b = p.find('}', a);
    if (b == std::string::npos) node.fail("unclosed ${ in '" + p + "'");
    const std::string var = p.substr(a + 2, b - a - 2);
    const char* v = std::getenv(var.c_str());
    if (!v || !*v) node.fail("environment variable " + var + " is not set (it names where the data is)");
    p.replace(a, b - a + 1, v);
  }
  return p;
}

// `twin: {sensor, keep_background, seed}` (SceneSource::twin_sensor).
void parse_twin(const YamlNode& t, const std::string& path, SceneSource& src) {
  t.check_keys({"sensor", "keep_background", "seed"});
  src.twin_sensor = t.get<std::string>("sensor");
  if (is_profile_file(src.twin_sensor)) {
    src.twin_sensor = resolve(path, src.twin_sensor);
    if (std::error_code ec; !fs::is_regular_file(src.twin_sensor, ec))
      t["sensor"].fail("sensor profile file not found: " + src.twin_sensor);
  } else {
    parse_sensor(t["sensor"]);  // a built-in name, or InputError naming the field
  }
  src.twin_keep_background = t.get_or<bool>("keep_background", false);
  const long long seed = t.get_or<long long>("seed", 1);
  if (seed < 0) t["seed"].fail("must be non-negative");
  src.twin_seed = static_cast<uint64_t>(seed);
}

}  // namespace

SceneSource parse_scene(const YamlNode& s, const std::string& path, const RecognitionSettings& settings,
                        std::set<std::string>& names) {
  s.check_keys({"name", "generate", "dataset", "clouds", "cloud", "split", "scene_ids", "images", "targets",
                "scenario", "generator", "settings", "refinements", "twin_of", "twin", "image_stride"});
  SceneSource src;
  src.generate = resolve(path, s.get_or<std::string>("generate", ""));
  src.dataset = resolve(path, expand_env(s["dataset"], s.get_or<std::string>("dataset", "")));
  for (const auto& c : s.get_or<std::vector<std::string>>("clouds", {})) src.clouds.push_back(resolve(path, c));
  if (s.has("twin")) {
    if (!s.has("twin_of")) s["twin"].fail("a twin names its real set: give 'twin_of'");
    parse_twin(s["twin"], path, src);
  }
  if (!src.generate.empty() + !src.dataset.empty() + !src.clouds.empty() + !src.twin_sensor.empty() != 1)
    s.fail("give exactly one of 'generate' (a scene config), 'dataset' (a BOP dataset), 'clouds' (point clouds) "
           "or 'twin' (the twin of another scene set)");
  for (size_t i = 0; i < src.clouds.size(); ++i)
    if (std::error_code ec; !fs::is_regular_file(src.clouds[i], ec)) s["clouds"].fail("cloud " + std::to_string(i) + " not found: " + src.clouds[i]);
  if (s.has("cloud")) {
    if (src.clouds.empty()) s["cloud"].fail("only valid with 'clouds'");
    s["cloud"].check_keys({"units", "intrinsics", "camera"});
    parse_cloud_units(s["cloud"].get_or<std::string>("units", "auto"), "cloud.units");
    src.cloud = s["cloud"].json();
    if (src.cloud.contains("camera")) src.cloud["camera"] = resolve(path, src.cloud["camera"].get<std::string>());
  }
  if (std::error_code ec; !src.generate.empty() && !fs::exists(src.generate, ec))
    s["generate"].fail("scene config not found: " + src.generate);
  if (!src.twin_sensor.empty() && !s.has("name")) s["twin"].fail("a twin needs a 'name'");
  src.name = s.get_or<std::string>(
      "name", fs::path(!src.generate.empty() ? src.generate : !src.dataset.empty() ? src.dataset : src.clouds.empty() ? "" : src.clouds[0])
                  .stem()
                  .string());
  if (!names.insert(src.name).second) s["name"].fail("duplicate scene name '" + src.name + "'");
  src.split = s.get_or<std::string>("split", "test");
  src.scene_ids = s.get_or<std::vector<int>>("scene_ids", {});
  src.images = s.get_or<int>("images", 0);
  if (src.images < 0) s["images"].fail("must be non-negative");
  src.image_stride = s.get_or<int>("image_stride", 1);
  if (src.image_stride < 1) s["image_stride"].fail("must be >= 1");
  src.targets = s.get_or<std::string>("targets", "");
  src.twin_of = s.get_or<std::string>("twin_of", "");
  src.scenario = s.get_or<std::string>(
      "scenario", src.name.rfind("warehouse", 0) == 0 ? std::string("warehouse") : std::string("table"));
  if (src.scenario != "table" && src.scenario != "warehouse")
    s["scenario"].fail("must be 'table' or 'warehouse'");
  src.refinements = s.get_or<std::vector<std::string>>("refinements", {});
  check_refinements(s["refinements"], src.refinements);
  if (s.has("generator")) {
    if (src.generate.empty()) s["generator"].fail("only valid with 'generate'");
    src.generator_overrides = s["generator"].json();
  }
  src.settings = parse_recognition_settings(s["settings"], settings);
  return src;
}


void resolve_twins(const YamlNode& scenes, std::vector<SceneSource>& sources) {
  for (size_t i = 0; i < scenes.size(); ++i) {
    SceneSource& twin = sources[i];
    if (twin.twin_of.empty()) continue;
    const auto real = std::find_if(sources.begin(), sources.end(),
                                   [&](const SceneSource& x) { return x.name == twin.twin_of; });
    if (twin.twin_of == twin.name || real == sources.end() || !real->twin_of.empty())
      scenes.at(i)["twin_of"].fail("must name another scene of this experiment that is no twin (the real set)");
    if (twin.twin_sensor.empty()) continue;
    if (real->dataset.empty())
      scenes.at(i)["twin_of"].fail("a generated twin needs a real set given by 'dataset'");
    for (const char* k : {"split", "scene_ids", "images", "image_stride", "targets", "scenario"})
      if (scenes.at(i).has(k)) scenes.at(i)[k].fail("a twin takes it from its real set");
    twin.split = real->split, twin.scene_ids = real->scene_ids, twin.images = real->images;
    twin.image_stride = real->image_stride;
    twin.targets = real->targets, twin.scenario = real->scenario;
  }
}

}  // namespace pb::experiment_detail
