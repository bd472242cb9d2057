// Scene generator: models, SceneGenerator and one layout attempt (the steps
// live in generator_layout.cpp and generator_render.cpp; the scene set
// writer in dataset.cpp).
#include "scenes/generator.h"

#include <algorithm>
#include <cmath>
#include <set>

#include "core/error.h"
#include "core/hash.h"
#include "core/random.h"
#include "core/rotation.h"
#include "models/procedural.h"
#include "models/registry.h"
#include "scenes/generator_internal.h"

namespace pb {

namespace scene_detail {

std::array<int, 4> bbox_of(int umin, int vmin, int umax, int vmax) {
  if (umax < umin) return {{-1, -1, 0, 0}};
  return {{umin, vmin, umax - umin + 1, vmax - vmin + 1}};
}

Polygon transform_footprint(const Polygon& local, double yaw, const Vec2& at) {
  const double c = std::cos(yaw), s = std::sin(yaw);
  Polygon out;
  for (const auto& p : local) out.emplace_back(at.x() + c * p.x() - s * p.y(), at.y() + s * p.x() + c * p.y());
  return out;
}

std::vector<const Placed*> Layout::objects() const {
  std::vector<const Placed*> out;
  for (const auto& o : objs) out.push_back(&o);
  return out;
}

std::vector<const Placed*> Layout::standing() const {
  std::vector<const Placed*> out = objects();
  if (occl.on) out.push_back(&occl.placed);
  return out;
}

namespace {

ModelRegistry open_registry(const SceneSettings& s) {
  if (s.registry.empty()) return ModelRegistry::load_default();
  try {
    return ModelRegistry::load(s.registry);
  } catch (const InputError& e) {
    throw InputError(s.config_file, "registry", e.what());
  }
}

// Loads one model (`field`: the config key that named it), scaled for the
// warehouse scenario, with its info and rest poses.
SceneModel load_scene_model(const SceneSettings& s, const ModelRegistry& reg, const std::string& name,
                            const std::string& field, RestPoses& rp) {
  SceneModel m;
  m.name = name;
  try {
    const ModelSpec& spec = reg.spec(name);
    m.obj_id = spec.obj_id;
    m.mesh = reg.load_model(name);
  } catch (const InputError& e) {
    const std::string what = e.what();
    throw InputError(s.config_file, field,
                     what.find(name) != std::string::npos ? what : "model '" + name + "': " + what);
  }
  if (s.scenario == Scenario::warehouse) {
    Rng r(derive_seed(s.seed, {kModelStream, stream_id(name)}));
    const double size = r.uniform(s.warehouse.object_size_mm.lo, s.warehouse.object_size_mm.hi);
    const double extent = m.mesh.bounds().sizes().maxCoeff();
    if (!(extent > 0)) throw InputError(s.config_file, field, "model '" + name + "' has an empty mesh");
    m.scale = size / extent;
    // Uniform scale: vertex normals keep their direction.
    for (auto& v : m.mesh.vertices) v *= static_cast<float>(m.scale);
  }
  m.info = reg.info(name, m.mesh);
  m.info.obj_id = m.obj_id;
  m.info.name = name;
  if (m.scale != 1.0) {
    for (auto& S : m.info.symmetries_discrete) S.block<3, 1>(0, 3) *= m.scale;
    for (auto& c : m.info.symmetries_continuous) c.offset *= m.scale;
  }
  rp = compute_rest_poses(m.mesh);
  if (rp.poses.empty())
    throw InputError(s.config_file, field, "model '" + name + "' has no stable rest pose (flat or degenerate mesh)");
  return m;
}

// The target and the pool models, sorted by obj_id; remembers the target and
// the pool.
void load_models(GeneratorState& G) {
  const SceneSettings& s = G.s;
  const ModelRegistry reg = open_registry(s);
  // Target first, then the pool, each name once.
  std::vector<std::pair<std::string, std::string>> names{{s.target, "target"}};
  for (const auto& n : s.distractors.pool)
    if (std::none_of(names.begin(), names.end(), [&](const auto& p) { return p.first == n; }))
      names.emplace_back(n, "distractors.pool");
  std::vector<SceneModel> loaded;
  std::vector<RestPoses> rests;
  for (const auto& [name, field] : names) {
    RestPoses rp;
    SceneModel m = load_scene_model(s, reg, name, field, rp);
    for (const auto& other : loaded)
      if (other.obj_id == m.obj_id)
        throw InputError(s.config_file, field,
                         "models '" + other.name + "' and '" + name + "' share obj_id " + std::to_string(m.obj_id));
    loaded.push_back(std::move(m));
    rests.push_back(std::move(rp));
  }
  // Sort by obj_id (models_info order), remember the target and the pool.
  std::vector<size_t> order(loaded.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return loaded[a].obj_id < loaded[b].obj_id; });
  for (size_t k = 0; k < order.size(); ++k) {
    const size_t i = order[k];
    if (loaded[i].name == s.target) G.target = static_cast<int>(k);
    G.models.push_back(std::move(loaded[i]));
    G.rest.push_back(std::move(rests[i]));
  }
  for (const auto& n : s.distractors.pool)
    for (size_t k = 0; k < G.models.size(); ++k)
      if (G.models[k].name == n && n != s.target) G.pool.push_back(static_cast<int>(k));
  if (s.distractors.max_count > 0 && G.pool.empty())
    throw InputError(s.config_file, "distractors.pool", "holds only the target; name other models");
}

// Convex hull vertices and bounding radius of every model.
void compute_hulls(GeneratorState& G) {
  for (size_t k = 0; k < G.models.size(); ++k) {
    const Mesh& mesh = G.models[k].mesh;
    std::vector<Vec3> V;
    for (const auto& v : mesh.vertices) V.push_back(v.cast<double>());
    const auto H = convex_hull_3d(V);
    std::set<int> idx;
    for (const auto& f : H)
      for (int j = 0; j < 3; ++j) idx.insert(f[j]);
    std::vector<Vec3> hv;
    for (int i : idx) hv.push_back(V[i]);
    double r = 0;
    for (const auto& v : V) r = std::max(r, v.norm());
    G.hull.push_back(std::move(hv));
    G.radius.push_back(r);
  }
}

GeneratorState make_state(const SceneSettings& settings) {
  GeneratorState G;
  G.s = settings;
  const SceneSettings& s = G.s;
  load_models(G);
  compute_hulls(G);
  G.table_mesh = make_box(s.table.size_mm, s.table.size_mm, s.table.thickness_mm);
  G.floor_mesh = make_box(s.warehouse.floor_size_mm, s.warehouse.floor_size_mm, s.warehouse.floor_thickness_mm);
  G.wall_mesh = make_box(s.warehouse.wall_length_mm, s.warehouse.wall_thickness_mm, s.warehouse.wall_height_mm);
  G.K = s.sensor.K;
  G.rset.near_mm = s.camera.near_mm;
  G.rset.far_mm = s.camera.far_mm;
  G.rset.normals = s.noise.model == "structured_light" || s.noise.model == "tof";
  return G;
}

}  // namespace

}  // namespace scene_detail

using namespace scene_detail;

SceneGenerator::SceneGenerator(const SceneSettings& settings)
    : impl_(std::make_unique<Impl>(make_state(settings))) {}

SceneGenerator::SceneGenerator(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

SceneGenerator::~SceneGenerator() = default;

std::unique_ptr<SceneGenerator> SceneGenerator::clone() const {
  const GeneratorState& state = *impl_;
  return std::unique_ptr<SceneGenerator>(new SceneGenerator(std::make_unique<Impl>(state)));
}

const SceneSettings& SceneGenerator::settings() const { return impl_->s; }
const std::vector<SceneModel>& SceneGenerator::models() const { return impl_->models; }
const SceneModel& SceneGenerator::model(const std::string& name) const {
  for (const auto& m : impl_->models)
    if (m.name == name) return m;
  throw InputError(impl_->s.config_file, "target", "no model '" + name + "' in this scene set");
}

SceneGenerator::Impl::Placed SceneGenerator::Impl::on_ground(int mi, int ri, double yaw, const Vec2& xy) const {
  return on_ground_rotated(mi, axis_angle(Vec3::UnitZ(), yaw) * rest[mi].poses[ri].R_rest, xy);
}

SceneGenerator::Impl::Placed SceneGenerator::Impl::on_ground_rotated(int mi, const Mat3& R, const Vec2& xy) const {
  Placed p;
  p.model = mi;
  p.mesh = &models[mi].mesh;
  double zmin = 1e300, zmax = -1e300;
  std::vector<Vec2> pts;
  pts.reserve(hull[mi].size());
  for (const auto& v : hull[mi]) {
    const Vec3 w = R * v;
    zmin = std::min(zmin, w.z());
    zmax = std::max(zmax, w.z());
    pts.emplace_back(w.x() + xy.x(), w.y() + xy.y());
  }
  p.T_world_model.R = R;
  p.T_world_model.t = Vec3(xy.x(), xy.y(), -zmin);
  p.footprint = convex_hull_2d(pts);
  p.height = zmax - zmin;
  p.radius = radius[mi];
  return p;
}

// Layout (see generator.h): target, camera, background, occluder footprint,
// other objects; then the target's visibility (occluder height) and the
// annotation. Every step draws from `rng` in this order.
bool SceneGenerator::Impl::generate_attempt(int im_id, int attempt, GeneratedImage& img, std::string& why) {
  if (s.setups > 0) return generate_setup_attempt(im_id, attempt, img, why);
  Rng rng(derive_seed(s.seed, {static_cast<uint64_t>(s.scene_id), static_cast<uint64_t>(im_id),
                               static_cast<uint64_t>(attempt)}));
  Layout L;
  L.objs.reserve(1 + s.distractors.max_count);
  place_target(rng, L);
  if (!place_camera(rng, L, img, why)) return false;
  place_background(rng, L);
  if (!fits(L, L.target(), {})) {
    why = "target does not fit (camera too close)";
    return false;
  }
  if (!place_occluder(rng, L, why) || !place_distractors(rng, L, why)) return false;
  AloneStats target_alone;
  if (!alone(L.target(), L.T_cam_world, target_alone) || target_alone.px_all == 0) {
    why = "target outside the image";
    return false;
  }
  if (!reach_visibility(L, target_alone, why)) return false;
  img.occluded = L.occl.on;
  img.occluder_height_mm = L.occl.height;
  annotate(L, target_alone, im_id, img);
  return true;
}

bool SceneGenerator::Impl::setup_layout(int k, Layout& L, std::string& why) {
  for (int attempt = 0; attempt < s.max_attempts; ++attempt) {
    Rng rng(derive_seed(s.seed, {static_cast<uint64_t>(s.scene_id), kSetupStream, static_cast<uint64_t>(k),
                                 static_cast<uint64_t>(attempt)}));
    L = Layout();
    L.objs.reserve(1 + s.distractors.max_count);
    GeneratedImage reference;
    place_target(rng, L);
    if (!place_camera(rng, L, reference, why)) continue;
    place_background(rng, L);
    if (!fits(L, L.target(), {})) {
      why = "target does not fit (camera too close)";
      continue;
    }
    if (!place_occluder(rng, L, why) || !place_distractors(rng, L, why)) continue;
    AloneStats target_alone;
    if (!alone(L.target(), L.T_cam_world, target_alone) || target_alone.px_all == 0) {
      why = "target outside the image";
      continue;
    }
    if (!reach_visibility(L, target_alone, why)) continue;
    L.full.reset();  // the reference camera's render
    return true;
  }
  why = "set-up " + std::to_string(k) + ": no valid layout (last: " + why + ")";
  return false;
}

bool SceneGenerator::Impl::generate_setup_attempt(int im_id, int attempt, GeneratedImage& img, std::string& why) {
  const int k = im_id % s.setups;
  auto made = setups_made.find(k);
  if (made == setups_made.end()) {
    SetUp u;
    u.ok = setup_layout(k, u.layout, u.why);
    made = setups_made.emplace(k, std::move(u)).first;
  }
  if (!made->second.ok) {
    why = made->second.why;
    return false;
  }
  Layout L = made->second.layout;  // this image's camera goes into its copy
  Rng rng(derive_seed(s.seed, {static_cast<uint64_t>(s.scene_id), static_cast<uint64_t>(im_id),
                               static_cast<uint64_t>(attempt)}));
  if (!place_camera(rng, L, img, why)) return false;
  for (const auto& p : L.objs)
    if (!clear_of_camera(L, p)) {
      why = "camera too close to an object";
      return false;
    }
  AloneStats target_alone;
  if (!alone(L.target(), L.T_cam_world, target_alone) || target_alone.px_all == 0) {
    why = "target outside the image";
    return false;
  }
  if (!reach_visibility(L, target_alone, why)) return false;
  annotate(L, target_alone, im_id, img);
  return true;
}

GeneratedImage SceneGenerator::generate(int im_id) {
  Impl& I = *impl_;
  std::string why;
  for (int attempt = 0; attempt < I.s.max_attempts; ++attempt) {
    GeneratedImage img;
    if (I.generate_attempt(im_id, attempt, img, why)) {
      img.attempts = attempt + 1;
      return img;
    }
  }
  const std::string field = I.s.occlusion.enabled ? "occlusion" : "min_target_visib";
  throw InputError(I.s.config_file, field,
                   "image " + std::to_string(im_id) + ": no valid layout in " + std::to_string(I.s.max_attempts) +
                       " attempts (last: " + why + "); relax the constraints or raise max_attempts");
}

}  // namespace pb
