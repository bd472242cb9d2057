// The model registry (models/models.yaml), in the BOP models_info spirit.
// Every model is normalized on load: millimetres, up axis -> +z, origin at
// the centre of its bounding box (as BOP requires), so symmetries, sizes and
// stable poses are all expressed in that frame.
#pragma once

#include <map>
#include <memory>
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
  // If set (all > 0), each axis is scaled on its own so the bounding box,
  // after the up axis is turned to +z, measures x, y, z mm: a stand-in
  // squeezed to another object's proportions (the armadillo to the
  // thesis's Statue of Liberty). Overrides `scale` and `fit_size`.
  std::optional<Vec3> fit_extent;
  std::string up = "+z";   // the file's up axis: +x -x +y -y +z -z
  std::string role = "target";  // "target" or "distractor" (informational)
  std::vector<Mat4> symmetries_discrete;  // in the normalized frame
  std::vector<ContinuousSymmetry> symmetries_continuous;
  std::string description;
};

// The diameter of BOP's models_info (largest distance between two vertices),
// exact, with a pruned search: the same value as Mesh::diameter() (which is
// O(n^2)), in milliseconds instead of seconds on a 35k-vertex mesh.
double exact_diameter(const Mesh& mesh);

class ModelRegistry {
 public:
  // Parses a registry file; InputError naming file and field on any bad entry
  // (unknown key, negative size, unknown up axis...). Missing mesh files are
  // not an error here: see available()/load_model().
  static ModelRegistry load(const std::string& registry_path);
  // The registry of the source tree: POSEBENCH_SOURCE_DIR/models/models.yaml,
  // or $POSEBENCH_MODELS when set.
  static ModelRegistry load_default();
  // The path load_default() reads: $POSEBENCH_MODELS (a file, or a folder
  // holding models.yaml) or POSEBENCH_SOURCE_DIR/models/models.yaml.
  static std::string default_path();

  const std::map<std::string, ModelSpec>& specs() const { return specs_; }
  const ModelSpec& spec(const std::string& name) const;  // InputError if unknown
  const ModelSpec& spec_by_id(int obj_id) const;          // InputError if unknown
  // Model names, sorted; only those of `role` when it is not empty.
  std::vector<std::string> names(const std::string& role = "") const;
  const std::string& file() const { return file_; }
  // Path of the mesh file ("" for generated ones).
  std::string mesh_path(const std::string& name) const;
  // Whether the mesh can be loaded; `why` gets a clear message if not.
  bool available(const std::string& name, std::string* why = nullptr) const;
  // Loads (or generates) and normalizes the mesh; InputError when missing.
  // Meshes are cached per registry (thread-safe): later calls return a copy.
  // (Named load_model, not load: a member load(name) cannot overload the
  // static load(registry_path) above, same parameter types.)
  Mesh load_model(const std::string& name) const;
  // The normalization load_model() applies: vertices * scale, rotation of the up
  // axis to +z, uniform scaling to fit_size (largest extent) when > 0, bbox
  // centre to the origin, vertex normals.
  static void normalize(Mesh* mesh, const ModelSpec& spec);
  // models_info entry (diameter, bbox, symmetries) for a loaded mesh.
  ModelInfo info(const std::string& name, const Mesh& mesh) const;

  // Where "shared:" sources are looked up: $POSEBENCH_SHARED_MODELS, else
  // POSEBENCH_SOURCE_DIR/../shared/models.
  std::string shared_models_dir;

 private:
  std::string file_;
  std::string base_dir_;
  std::map<std::string, ModelSpec> specs_;
  struct Cache;
  std::shared_ptr<Cache> cache_;  // shared by copies of this registry
};

}  // namespace pb
