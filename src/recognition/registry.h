// The method registry: every descriptor method and every refinement method
// by name, listed in one place (registry.cpp), so one binary covers them all
// and a config selects them. PCL-free.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/yaml.h"
#include "recognition/method.h"
#include "recognition/refine/refiner.h"

namespace pb {

struct RecognitionSettings;

struct DescriptorEntry {
  std::string name;
  std::string section;  // the settings section the method reads ("local", "global", "ppf")
  std::unique_ptr<Method> (*make)(const RecognitionSettings& s);  // passes that section alone
};

struct RefinementEntry {
  std::string name;
  std::string section;  // the subsection of `refine` the method reads besides the common settings
                        // ("icp", "gicp", "ndt"; "" = none)
  // Builds the method with the common settings and that subsection alone;
  // null for "none" (no registration).
  std::unique_ptr<Refiner> (*make)(const RefineSettings& s);
};

const std::vector<DescriptorEntry>& descriptor_registry();
const std::vector<RefinementEntry>& refinement_registry();
std::vector<std::string> descriptor_names();
std::vector<std::string> refinement_names();

// Lookups: InputError(file, field) naming the allowed names when unknown.
const DescriptorEntry& descriptor_entry(const std::string& name, const std::string& file = "",
                                        const std::string& field = "descriptor");
const RefinementEntry& refinement_entry(const std::string& name, const std::string& file = "",
                                        const std::string& field = "refinement");
// The node's string if it is one of `allowed`, else fails at the node.
std::string check_name(const YamlNode& node, const std::vector<std::string>& allowed);

std::unique_ptr<Method> make_method(const RecognitionSettings& s);  // for s.descriptor
// The refinement method `name` (InputError when unknown); null for "none".
std::unique_ptr<Refiner> make_refiner(const std::string& name, const RefineSettings& s);
// refine_pose (refine/refine.h) with the refinement method built by name
// (none icp icp_lm icp_plane icp_pcl icp_plane_pcl gicp ndt; InputError
// otherwise).
RefineResult refine_pose(const std::string& method, const PointSet& model, const PointSet& scene, const Pose& init,
                         const RefineSettings& s, uint64_t seed, const KdTree3* scene_tree = nullptr);

}  // namespace pb
