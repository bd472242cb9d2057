// parse_ppf: the `ppf:` YAML section (PpfSettings, ppf.h). Kept apart from
// ppf_method.cpp so that settings parsing compiles without PCL.
#include "core/error.h"
#include "recognition/ppf/ppf.h"

namespace pb {

void parse_ppf(const YamlNode& node, PpfSettings& s) {
  if (!node.defined()) return;
  node.check_keys({"model_points", "angle_step_deg", "distance_step_fraction", "scene_reference_fraction",
                   "position_cluster_mm", "rotation_cluster_deg", "max_hypotheses"});
  auto int_at_least = [&](const std::string& key, int& v, int min_value) {
    if (!node.has(key)) return;
    const int x = node.get<int>(key);
    if (x < min_value) node[key].fail("must be at least " + std::to_string(min_value) + ", got " + std::to_string(x));
    v = x;
  };
  int_at_least("model_points", s.model_points, 10);
  if (s.model_points > 5000)
    node["model_points"].fail("must be at most 5000 (the model's pair features grow with its square)");
  s.angle_step_deg = node.get_positive("angle_step_deg", s.angle_step_deg);
  if (s.angle_step_deg > 90) node["angle_step_deg"].fail("must be at most 90");
  s.distance_step_fraction = node.get_positive("distance_step_fraction", s.distance_step_fraction);
  if (s.distance_step_fraction > 1) node["distance_step_fraction"].fail("must be at most 1");
  s.scene_reference_fraction = node.get_positive("scene_reference_fraction", s.scene_reference_fraction);
  if (s.scene_reference_fraction > 1) node["scene_reference_fraction"].fail("must be at most 1");
  s.position_cluster_mm = node.get_positive("position_cluster_mm", s.position_cluster_mm);
  s.rotation_cluster_deg = node.get_positive("rotation_cluster_deg", s.rotation_cluster_deg);
  int_at_least("max_hypotheses", s.max_hypotheses, 1);
}

}  // namespace pb
