// A BOP-layout dataset from point clouds (io/cloud.h): one scene whose
// images are the clouds, as depth PNGs with their intrinsics, without
// ground truth, and the objects' models from the model registry. What
// `posebench import-clouds` writes and experiment configs' `clouds:` scene
// sets run on.
#pragma once

#include <string>
#include <vector>

#include "core/types.h"
#include "io/cloud.h"

namespace pb {

// One cloud as the pipeline takes it: a depth image with its intrinsics.
struct CloudScene {
  DepthImage depth;
  Intrinsics K;
  std::string source;  // of the intrinsics: "given", "camera.json", "fitted", "virtual"
};
// `intrinsics` ("fx,fy,cx,cy[,width,height]") or `camera` (a BOP
// camera.json) when given (not both); else fitted to an organized cloud or
// a virtual 640x480 camera for an unorganized one. An organized cloud whose
// size is the intrinsics' keeps its grid; any other is projected.
CloudScene cloud_scene(const PointCloudFile& cloud, const std::string& path, const std::string& intrinsics,
                       const std::string& camera);

struct ImportCloudsSettings {
  std::vector<std::string> clouds;  // .pcd / .ply files: image i of scene 1 is clouds[i]
  CloudUnits units = CloudUnits::automatic;
  std::string intrinsics;           // "fx,fy,cx,cy[,width,height]" for every cloud ("" = see below)
  std::string camera;               // or a BOP camera.json for every cloud
  // Without either: organized clouds keep their grid with intrinsics fitted
  // to their points, unorganized ones go through a virtual 640x480 camera.
  std::vector<std::string> objects; // registry names written to models/
  std::string registry;             // registry file ("" = the default)
};

struct ImportCloudsSummary {
  int images = 0;
  double depth_scale = 0.1;         // mm per PNG unit (0.1; 1.0 when a depth exceeds 6.5 m)
  std::vector<std::string> intrinsics_source;  // per image: "given", "camera.json", "fitted", "virtual"
};

// Writes the dataset into `out` (created; an existing non-empty folder that
// is not such a dataset is an InputError, as for the generator). InputError
// naming the cloud and field for a bad cloud, the field for bad settings.
ImportCloudsSummary import_clouds(const ImportCloudsSettings& settings, const std::string& out);

}  // namespace pb
