// BOP-style symmetries in YAML (models/models.yaml entries, experiment
// `judgements`): symmetries_discrete as 4x4 rigid transforms (16 numbers
// row-major or 4 rows of 4, translation in mm) and symmetries_continuous as
// {axis: [x, y, z], offset: [x, y, z]}. One reader for both places.
#pragma once

#include <vector>

#include "core/yaml.h"
#include "io/bop.h"

namespace pb {

// Reads the optional keys symmetries_discrete and symmetries_continuous of
// the map `node` (appending); InputError naming file, line and key on a
// malformed matrix, a non-rotation, a zero axis.
void read_symmetries(const YamlNode& node, std::vector<Mat4>& discrete, std::vector<ContinuousSymmetry>& continuous);

}  // namespace pb
