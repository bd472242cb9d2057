// The registry: descriptor methods (each built with its own settings
// section) and refinement methods, by name.
#include "recognition/registry.h"

#include <algorithm>

#include "core/error.h"
#include "recognition/pcl_console.h"
#include "recognition/recognition_settings.h"

namespace pb {

const std::vector<DescriptorEntry>& descriptor_registry() {
  static const std::vector<DescriptorEntry> v = {
      {"fpfh", "local", [](const RecognitionSettings& s) { return make_fpfh_method(s.local); }},
      {"shot", "local", [](const RecognitionSettings& s) { return make_shot_method(s.local); }},
      {"cvfh", "global", [](const RecognitionSettings& s) { return make_cvfh_method(s.global); }},
      {"esf", "global", [](const RecognitionSettings& s) { return make_esf_method(s.global); }},
      {"cesf", "global", [](const RecognitionSettings& s) { return make_cesf_method(s.global); }},
      {"ourcvfh", "global", [](const RecognitionSettings& s) { return make_ourcvfh_method(s.global); }},
      {"ppf", "ppf", [](const RecognitionSettings& s) { return make_ppf_method(s.ppf); }},
  };
  return v;
}

const std::vector<RefinementEntry>& refinement_registry() {
  // Each factory takes the RegistrationSettings part of `refine` and its own
  // subsection.
  static const std::vector<RefinementEntry> v = {
      {"none", "", [](const RefineSettings&) { return std::unique_ptr<Refiner>(); }},
      {"icp", "icp", [](const RefineSettings& s) { return make_icp_refiner(s, s.icp); }},
      {"icp_lm", "", [](const RefineSettings& s) { return make_icp_lm_refiner(s); }},
      {"icp_plane", "icp", [](const RefineSettings& s) { return make_icp_plane_refiner(s, s.icp); }},
      {"icp_pcl", "icp", [](const RefineSettings& s) { return make_icp_pcl_refiner(s, s.icp); }},
      {"icp_plane_pcl", "", [](const RefineSettings& s) { return make_icp_plane_pcl_refiner(s); }},
      {"gicp", "gicp", [](const RefineSettings& s) { return make_gicp_refiner(s, s.gicp); }},
      {"ndt", "ndt", [](const RefineSettings& s) { return make_ndt_refiner(s, s.ndt); }},
  };
  return v;
}

namespace {

template <typename E>
std::vector<std::string> names_of(const std::vector<E>& v) {
  std::vector<std::string> n;
  for (const auto& e : v) n.push_back(e.name);
  return n;
}

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
  return s;
}

template <typename E>
const E& find_entry(const std::vector<E>& v, const std::string& name, const std::string& file,
                    const std::string& field, const char* what) {
  for (const auto& e : v)
    if (e.name == name) return e;
  throw InputError(file, field, std::string("unknown ") + what + " '" + name + "' (allowed: " + join(names_of(v)) + ")");
}

}  // namespace

std::vector<std::string> descriptor_names() { return names_of(descriptor_registry()); }
std::vector<std::string> refinement_names() { return names_of(refinement_registry()); }

const DescriptorEntry& descriptor_entry(const std::string& name, const std::string& file, const std::string& field) {
  return find_entry(descriptor_registry(), name, file, field, "descriptor");
}

const RefinementEntry& refinement_entry(const std::string& name, const std::string& file, const std::string& field) {
  return find_entry(refinement_registry(), name, file, field, "refinement");
}

std::string check_name(const YamlNode& node, const std::vector<std::string>& allowed) {
  const std::string v = node.as<std::string>();
  if (std::find(allowed.begin(), allowed.end(), v) == allowed.end())
    node.fail("unknown name '" + v + "' (allowed: " + join(allowed) + ")");
  return v;
}

std::unique_ptr<Method> make_method(const RecognitionSettings& s) {
  silence_pcl_console();
  return descriptor_entry(s.descriptor).make(s);
}

std::unique_ptr<Refiner> make_refiner(const std::string& name, const RefineSettings& s) {
  return refinement_entry(name).make(s);
}

RefineResult refine_pose(const std::string& method, const PointSet& model, const PointSet& scene, const Pose& init,
                         const RefineSettings& s, uint64_t seed, const KdTree3* scene_tree) {
  const std::unique_ptr<Refiner> refiner = make_refiner(method, s);
  return refine_pose(refiner.get(), model, scene, init, s, seed, scene_tree);
}

}  // namespace pb
