// The model registry (models/models.yaml), in the BOP models_info spirit.
// Every model is normalized on load: millimetres, up axis -> +z, origin at
// the centre of its bounding box (as BOP requires), so symmetries, sizes and
// stable poses are all expressed in that frame.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/types.h"
#include "io/bop.h"

namespace pb {

struct ModelSpec {
  std::string name;        // registry key, e.g. "milk_carton"
  int obj_id = 0;          // BOP object id used when writing datasets
  // "generated:KIND" for the project's procedural models, "shared:FILE" for
  // ../shared/models/FILE, otherwise a path relative to the registry file.
  std::string source;
  double scale = 1.0;      // file units -> mm (applied before fit_size)
  // If > 0, the mesh is scaled uniformly so its largest extent equals this
  // (mm); overrides `scale`.
  double fit_size = 0.0;
  std::string up = "+z";   // the file's up axis: +x -x +y -y +z -z
  std::string role = "target";  // "target" or "distractor" (informational)
  std::vector<Mat4> symmetries_discrete;  // in the normalized frame
  std::vector<ContinuousSymmetry> symmetries_continuous;
  std::string description;
};

class ModelRegistry {
 public:
  // Parses a registry file; InputError naming file and field on any bad entry
  // (unknown key, negative size, unknown up axis...). Missing mesh files are
  // not an error here: see available()/load().
  static ModelRegistry load(const std::string& registry_path);
  // The registry of the source tree: POSEBENCH_SOURCE_DIR/models/models.yaml,
  // or $POSEBENCH_MODELS when set.
  static ModelRegistry load_default();

  const std::map<std::string, ModelSpec>& specs() const { return specs_; }
  const ModelSpec& spec(const std::string& name) const;  // InputError if unknown
  // Path of the mesh file ("" for generated ones).
  std::string mesh_path(const std::string& name) const;
  // Whether the mesh can be loaded; `why` gets a clear message if not.
  bool available(const std::string& name, std::string* why = nullptr) const;
  // Loads (or generates) and normalizes the mesh; InputError when missing.
  Mesh load(const std::string& name) const;
  // models_info entry (diameter, bbox, symmetries) for a loaded mesh.
  ModelInfo info(const std::string& name, const Mesh& mesh) const;

  std::string shared_models_dir;  // where "shared:" sources are looked up

 private:
  std::string file_;
  std::string base_dir_;
  std::map<std::string, ModelSpec> specs_;
};

}  // namespace pb
