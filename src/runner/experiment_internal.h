// Parts of the experiment loader (experiment.cpp) that the scene-source
// parser (scene_source.cpp) shares with it. Not for other callers.
#pragma once

#include <set>
#include <string>
#include <vector>

#include "core/yaml.h"
#include "runner/experiment.h"

namespace pb::experiment_detail {

// A path from a config: as given when it exists from the working directory
// (the usual case: run from the project root), else relative to the config's
// folder.
std::string resolve(const std::string& base_file, const std::string& p);
// InputError at `node` for a refinement name the registry does not know.
void check_refinements(const YamlNode& node, const std::vector<std::string>& names);
// One entry of `scenes:`, its settings read over `settings` (the
// experiment's); `names` collects the names seen (duplicates fail).
SceneSource parse_scene(const YamlNode& s, const std::string& path, const RecognitionSettings& settings,
                        std::set<std::string>& names);
// Each twin_of names a real set of the experiment; a generated twin takes
// its real set's split, scene_ids, images, image_stride, targets and
// scenario.
void resolve_twins(const YamlNode& scenes, std::vector<SceneSource>& sources);

}  // namespace pb::experiment_detail
