// What `posebench recognize` works on: one depth image with its intrinsics
// (and ground truth where the source has it), from a BOP dataset image or a
// point-cloud file, and one object model, from the dataset, the model
// registry or a mesh file.
#pragma once

#include <nlohmann/json.hpp>

#include <string>

#include "core/types.h"
#include "io/bop.h"

namespace pbcli {

struct RecognizeSource {
  // A BOP dataset image ...
  std::string dataset_dir, split;
  int scene = -1, image = -1;
  // ... or a point cloud (.pcd, .ply) with optional intrinsics.
  std::string cloud, units = "auto";
  std::string intrinsics;  // "fx,fy,cx,cy" or "fx,fy,cx,cy,width,height"
  std::string camera;      // a BOP camera.json
  // The object: an id or name in the dataset (or the registry without a
  // dataset), or a model file: a mesh in mm, or a point cloud (.pcd, or .ply
  // without faces) of the object scanned from one side, in `model_units`.
  std::string object, model, model_units = "auto";
};

struct RecognizeScene {
  pb::DepthImage depth;
  pb::ImageInfo im;                // K with its size; ground truth (none for clouds)
  // The scene's first image, where relative lengths take the sensor's floor
  // as in `posebench run` (resolve_for_scene); a point cloud is its own.
  pb::DepthImage first_depth;
  pb::Intrinsics first_K;
  nlohmann::ordered_json source;   // what the JSON output says of the input
  std::string description;         // the same in words
};

struct RecognizeObject {
  int obj_id = 0;
  std::string name;
  pb::Mesh mesh;                   // a cloud model: its points in the model frame, no faces
  pb::ModelInfo info;              // symmetries (none for a model file)
  std::vector<pb::Vec3f> cloud;    // a cloud model (.pcd, or .ply without faces): its points as scanned (mm)
};

// Checks which source is given (InputError field "--cloud" / "--dataset"
// when neither or both are), then reads it. Clouds: organized ones keep
// their pixel grid (intrinsics fitted to the points unless given), others
// are projected through the given intrinsics or a virtual camera.
RecognizeScene load_recognize_scene(RecognizeSource& src);
RecognizeObject load_recognize_object(const RecognizeSource& src);

}  // namespace pbcli
