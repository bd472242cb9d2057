// RecognitionSettings <-> YAML / JSON: assembles the stage sections, each
// parsed and serialized from its own field list.
#include "recognition/settings.h"

#include "recognition/registry.h"

namespace pb {

const std::vector<std::string>& recognition_sections() {
  static const std::vector<std::string> v{"views", "preprocess", "local", "global", "ppf", "refine", "verify"};
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
  for_each_section(s, [&](const char* name, auto& section) { parse_section(node[name], section); });
  if (node.has("seed")) {
    const YamlNode n = node["seed"];
    const std::string text = n.as<std::string>();
    if (text.empty() || text[0] == '-') n.fail("must be a non-negative integer");
    s.seed = n.as<unsigned long long>();
  }
  return s;
}

nlohmann::ordered_json recognition_settings_json(const RecognitionSettings& settings) {
  RecognitionSettings s = settings;
  nlohmann::ordered_json j;
  j["descriptor"] = s.descriptor;
  j["refinement"] = s.refinement;
  for_each_section(s, [&](const char* name, const auto& section) { j[name] = section_json(section); });
  j["seed"] = s.seed;
  return j;
}

std::string settings_to_json(const RecognitionSettings& s) { return recognition_settings_json(s).dump(); }

}  // namespace pb
