// The model registry: models/models.yaml parsed with file- and line-aware
// errors, meshes loaded (assimp) or generated (procedural.cpp) and
// normalized to millimetres, up = +z, origin at the bounding box centre.
#include "models/registry.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <set>

#include "core/error.h"
#include "core/yaml.h"
#include "io/mesh_io.h"
#include "io/symmetry_yaml.h"
#include "models/procedural.h"

#ifndef POSEBENCH_SOURCE_DIR
#define POSEBENCH_SOURCE_DIR "."
#endif

namespace fs = std::filesystem;

namespace pb {

namespace {

const char* kGenerated = "generated:";
const char* kShared = "shared:";

bool starts_with(const std::string& s, const std::string& p) { return s.rfind(p, 0) == 0; }

// Rotation taking the file's up axis to +z.
Mat3 up_rotation(const std::string& up) {
  const Vec3 ex = Vec3::UnitX(), ey = Vec3::UnitY();
  if (up == "+z") return Mat3::Identity();
  if (up == "-z") return Eigen::AngleAxisd(M_PI, ex).toRotationMatrix();
  if (up == "+y") return Eigen::AngleAxisd(M_PI / 2, ex).toRotationMatrix();   // y -> z
  if (up == "-y") return Eigen::AngleAxisd(-M_PI / 2, ex).toRotationMatrix();  // -y -> z
  if (up == "+x") return Eigen::AngleAxisd(-M_PI / 2, ey).toRotationMatrix();  // x -> z
  if (up == "-x") return Eigen::AngleAxisd(M_PI / 2, ey).toRotationMatrix();   // -x -> z
  throw std::invalid_argument("up axis " + up);
}

// Exact signs for the axis permutations (AngleAxis leaves 1e-17 residues).
Mat3 clean(Mat3 R) {
  for (int i = 0; i < 9; ++i) R.data()[i] = std::round(R.data()[i]);
  return R;
}

}  // namespace

double exact_diameter(const Mesh& mesh) {
  // Sort by distance r from the bbox centre c, largest first. For any pair,
  // |a - b| <= r_a + r_b, so once r_i + r_j cannot beat the best distance
  // found, no later j (smaller r) can either, and once 2 r_i cannot, no
  // later i can. Exact, and near-linear on real meshes.
  const size_t n = mesh.vertices.size();
  if (n < 2) return 0.0;
  const Vec3 c = mesh.bounds().center().cast<double>();
  std::vector<std::pair<double, Vec3>> pts(n);
  for (size_t i = 0; i < n; ++i) {
    const Vec3 p = mesh.vertices[i].cast<double>();
    pts[i] = {(p - c).norm(), p};
  }
  std::sort(pts.begin(), pts.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  double best2 = 0, best = 0;
  for (size_t i = 0; i < n; ++i) {
    if (2 * pts[i].first < best) break;
    for (size_t j = i + 1; j < n; ++j) {
      if (pts[i].first + pts[j].first < best) break;
      const double d2 = (pts[i].second - pts[j].second).squaredNorm();
      if (d2 > best2) {
        best2 = d2;
        best = std::sqrt(d2);
      }
    }
  }
  return best;
}

struct ModelRegistry::Cache {
  std::mutex mutex;
  std::map<std::string, Mesh> meshes;
};

ModelRegistry ModelRegistry::load(const std::string& registry_path) {
  ModelRegistry reg;
  reg.file_ = registry_path;
  reg.base_dir_ = fs::path(registry_path).parent_path().string();
  if (const char* env = std::getenv("POSEBENCH_SHARED_MODELS"); env && *env)
    reg.shared_models_dir = env;
  else
    reg.shared_models_dir = (fs::path(POSEBENCH_SOURCE_DIR) / ".." / "shared" / "models").lexically_normal().string();
  reg.cache_ = std::make_shared<Cache>();

  const YamlNode root = YamlNode::load_file(registry_path);
  root.check_keys({"models"});
  const YamlNode models = root["models"];
  if (!models.defined() || !models.is_map()) models.fail("expected a mapping of model names to entries");
  std::set<int> ids;
  const std::set<std::string> ups = {"+x", "-x", "+y", "-y", "+z", "-z"};
  const std::set<std::string> roles = {"target", "distractor", "occluder"};
  for (const std::string& name : models.keys()) {
    if (reg.specs_.count(name)) models[name].fail("duplicate model name '" + name + "'");
    const YamlNode e = models[name];
    // Names must not read as object ids ("3", "obj_000003"): BopDataset::
    // resolve_object accepts all three forms.
    const bool name_ok = !name.empty() && std::isalpha(static_cast<unsigned char>(name[0])) &&
                         name.rfind("obj_", 0) != 0 &&
                         std::all_of(name.begin(), name.end(), [](char ch) {
                           return std::isalnum(static_cast<unsigned char>(ch)) || ch == '_' || ch == '-' || ch == '.';
                         });
    if (!name_ok)
      e.fail("model name '" + name + "' must start with a letter, use only letters, digits, _ - . and not start with obj_");
    if (!e.is_map()) e.fail("expected a mapping (obj_id, source, ...)");
    e.check_keys({"obj_id", "source", "scale", "fit_size", "fit_extent", "up", "role", "symmetries_discrete",
                  "symmetries_continuous", "description"});
    ModelSpec s;
    s.name = name;
    s.obj_id = e.get<int>("obj_id");
    if (s.obj_id <= 0) e["obj_id"].fail("must be a positive integer");
    if (!ids.insert(s.obj_id).second) e["obj_id"].fail("obj_id " + std::to_string(s.obj_id) + " is used twice");
    s.source = e.get<std::string>("source");
    if (starts_with(s.source, kGenerated)) {
      try {
        make_procedural(s.source.substr(std::string(kGenerated).size()));
      } catch (const InputError& err) {
        // make_procedural's message reads "field 'source': WHY": keep WHY.
        std::string why = err.what();
        const std::string prefix = "field 'source': ";
        if (starts_with(why, prefix)) why = why.substr(prefix.size());
        e["source"].fail(why);
      }
    } else if (starts_with(s.source, kShared)) {
      if (s.source.size() == std::string(kShared).size()) e["source"].fail("missing file name after 'shared:'");
    } else if (s.source.empty()) {
      e["source"].fail("empty source");
    }
    s.scale = e.get_positive("scale", 1.0);
    s.fit_size = e.get_nonnegative("fit_size", 0.0);
    if (const YamlNode fe = e["fit_extent"]; fe.defined()) {
      if (!fe.is_sequence() || fe.size() != 3) fe.fail("must be [x, y, z] in mm");
      Vec3 v;
      for (size_t i = 0; i < 3; ++i) {
        v[static_cast<int>(i)] = fe.at(i).as<double>();
        if (!(v[static_cast<int>(i)] > 0) || !std::isfinite(v[static_cast<int>(i)]))
          fe.at(i).fail("must be a positive length in mm");
      }
      s.fit_extent = v;
    }
    s.up = e.get_or<std::string>("up", "+z");
    if (!ups.count(s.up)) e["up"].fail("unknown up axis '" + s.up + "' (one of +x -x +y -y +z -z)");
    s.role = e.get_or<std::string>("role", "target");
    if (!roles.count(s.role)) e["role"].fail("unknown role '" + s.role + "' (target, distractor or occluder)");
    s.description = e.get_or<std::string>("description", "");
    read_symmetries(e, s.symmetries_discrete, s.symmetries_continuous);
    reg.specs_[name] = s;
  }
  return reg;
}

std::string ModelRegistry::default_path() {
  if (const char* env = std::getenv("POSEBENCH_MODELS"); env && *env) {
    std::error_code ec;
    if (fs::is_directory(env, ec)) return (fs::path(env) / "models.yaml").string();
    return env;
  }
  return (fs::path(POSEBENCH_SOURCE_DIR) / "models" / "models.yaml").string();
}

ModelRegistry ModelRegistry::load_default() { return load(default_path()); }

const ModelSpec& ModelRegistry::spec(const std::string& name) const {
  auto it = specs_.find(name);
  if (it == specs_.end()) {
    std::string known;
    for (const auto& [n, s] : specs_) known += (known.empty() ? "" : ", ") + n;
    throw InputError(file_, "model", "unknown model '" + name + "' (known: " + known + ")");
  }
  return it->second;
}

const ModelSpec& ModelRegistry::spec_by_id(int obj_id) const {
  for (const auto& [n, s] : specs_)
    if (s.obj_id == obj_id) return s;
  throw InputError(file_, "obj_id", "no model with obj_id " + std::to_string(obj_id));
}

std::vector<std::string> ModelRegistry::names(const std::string& role) const {
  std::vector<std::string> out;
  for (const auto& [n, s] : specs_)
    if (role.empty() || s.role == role) out.push_back(n);
  return out;
}

std::string ModelRegistry::mesh_path(const std::string& name) const {
  const ModelSpec& s = spec(name);
  if (starts_with(s.source, kGenerated)) return "";
  if (starts_with(s.source, kShared))
    return (fs::path(shared_models_dir) / s.source.substr(std::string(kShared).size())).string();
  const fs::path p(s.source);
  return p.is_absolute() ? p.string() : (fs::path(base_dir_) / p).lexically_normal().string();
}

bool ModelRegistry::available(const std::string& name, std::string* why) const {
  const ModelSpec& s = spec(name);
  if (starts_with(s.source, kGenerated)) return true;
  const std::string path = mesh_path(name);
  std::error_code ec;
  std::string problem;
  if (!fs::exists(path, ec))
    problem = "not found";
  else if (!fs::is_regular_file(path, ec))
    problem = "is not a regular file";
  else if (!std::ifstream(path, std::ios::binary))
    problem = "is not readable";
  if (problem.empty()) return true;
  if (why) {
    *why = "model '" + name + "' (" + file_ + "): mesh file " + path + " " + problem;
    if (starts_with(s.source, kShared))
      *why += " (shared models are read from " + shared_models_dir +
              "; set POSEBENCH_SHARED_MODELS to their folder)";
  }
  return false;
}

Mesh ModelRegistry::load_model(const std::string& name) const {
  const ModelSpec& s = spec(name);
  const std::string key = name + "\n" + mesh_path(name);  // shared_models_dir may change
  if (cache_) {
    std::lock_guard<std::mutex> lock(cache_->mutex);
    auto it = cache_->meshes.find(key);
    if (it != cache_->meshes.end()) return it->second;
  }
  Mesh m;
  if (starts_with(s.source, kGenerated)) {
    m = make_procedural(s.source.substr(std::string(kGenerated).size()));
  } else {
    std::string why;
    if (!available(name, &why)) throw InputError(mesh_path(name), "mesh", why);
    m = load_mesh(mesh_path(name));
  }
  normalize(&m, s);
  if (cache_) {
    std::lock_guard<std::mutex> lock(cache_->mutex);
    cache_->meshes.emplace(key, m);
  }
  return m;
}

void ModelRegistry::normalize(Mesh* m, const ModelSpec& s) {
  // 1. file units -> mm, 2. up axis -> +z, 3. fit_extent or fit_size,
  // 4. bbox centre at 0.
  Pose T;
  T.R = clean(up_rotation(s.up));
  for (auto& v : m->vertices) v *= static_cast<float>(s.scale);
  m->transform(T);
  if (s.fit_extent) {
    const Eigen::AlignedBox3f b = m->bounds();
    const Eigen::Vector3f size = b.max() - b.min();
    Eigen::Vector3f k = Eigen::Vector3f::Ones();
    for (int a = 0; a < 3; ++a)
      if (size[a] > 0) k[a] = static_cast<float>((*s.fit_extent)[a] / size[a]);
    for (auto& v : m->vertices) v = v.cwiseProduct(k);
  } else if (s.fit_size > 0) {
    const Eigen::AlignedBox3f b = m->bounds();
    const double extent = (b.max() - b.min()).maxCoeff();
    if (extent > 0) {
      const float k = static_cast<float>(s.fit_size / extent);
      for (auto& v : m->vertices) v *= k;
    }
  }
  const Eigen::AlignedBox3f b = m->bounds();
  Pose C;
  C.t = -b.center().cast<double>();
  m->transform(C);
  m->compute_vertex_normals();
}

ModelInfo ModelRegistry::info(const std::string& name, const Mesh& mesh) const {
  const ModelSpec& s = spec(name);
  ModelInfo i;
  i.obj_id = s.obj_id;
  i.name = s.name;
  i.diameter = exact_diameter(mesh);
  const Eigen::AlignedBox3f b = mesh.bounds();
  i.min = b.min().cast<double>();
  i.size = (b.max() - b.min()).cast<double>();
  i.symmetries_discrete = s.symmetries_discrete;
  i.symmetries_continuous = s.symmetries_continuous;
  return i;
}

}  // namespace pb
