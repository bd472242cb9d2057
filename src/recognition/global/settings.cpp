// GlobalSettings: the check across fields (the fields are in global.h).
#include <string>

#include "recognition/global/global.h"

namespace pb {

void GlobalSettings::validate(const YamlNode& node) const {
  if (cluster_max_points < cluster_min_points)
    node["cluster_max_points"].fail("must be at least cluster_min_points (" + std::to_string(cluster_min_points) +
                                    ")");
}

}  // namespace pb
