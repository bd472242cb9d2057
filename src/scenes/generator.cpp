// Scene generator (scenes/generator.h): the models, SceneGenerator and one
// layout attempt, in its steps: the layout (target, camera, background,
// occluder footprint and other objects, each drawing from the attempt's
// random stream in a fixed order), then the renders (silhouettes of single
// objects, the target's visibility and the occluder height search, and the
// final annotated image). The scene set writer is dataset.cpp.
#include "scenes/generator.h"

#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "core/error.h"
#include "core/hash.h"
#include "core/random.h"
#include "core/rotation.h"
#include "core/types.h"
#include "models/procedural.h"
#include "models/registry.h"
#include "render/renderer.h"
#include "render/sensor.h"
#include "scenes/rest_poses.h"

namespace pb {
namespace scene_detail {

constexpr uint64_t kModelStream = 0x6d6f64656cull;  // "model"
constexpr int kOccluderLabel = 1000;
constexpr int kBackgroundLabel = 2000;

using Vec2 = Eigen::Vector2d;
using Polygon = std::vector<Vec2>;

// An object standing on the ground plane.
struct Placed {
  int model = -1;           // index into Impl::models, -1 for unannotated objects
  const Mesh* mesh = nullptr;
  Pose T_world_model;
  Polygon footprint;        // convex, counter-clockwise, world xy
  double height = 0;        // top above the ground
  double radius = 0;        // bounding sphere radius about the model origin
};

struct AloneStats {
  int px_all = 0;
  std::array<int, 4> bbox{{-1, -1, 0, 0}};
  std::vector<int> pixels;  // silhouette pixels inside the image (v * W + u)
  bool tiled = false;       // crossed the border: rendered in shifted tiles, not with the image's own K
};

// The occluder of an occluded image: its footprint is placed with the
// layout, its height is searched once everything else stands.
struct Occluder {
  bool on = false;          // this image gets an occluder
  double goal = 0;          // visible fraction of the target aimed at
  bool box = true;          // box, else an upright cylinder
  double w = 0, d = 0;      // box width (across the view) and depth (mm)
  double r = 0;             // cylinder radius (mm)
  double hmax = 0;          // tallest height tried (mm)
  double height = 0;        // the height found (mm)
  Placed placed;
  Mesh mesh;                // rebuilt for each height tried
};

// One layout attempt. Not copied or moved once objects point into it.
struct Layout {
  std::vector<Placed> objs;      // annotated objects, the target first
  std::vector<Placed> bg;        // table, or floor and wall
  Pose T_world_cam, T_cam_world;
  Vec3 eye = Vec3::Zero();
  double dist = 0;               // camera distance to the look-at point (mm)
  Vec2 g = Vec2::Zero();         // unit ground direction from the target towards the camera
  Vec2 perp = Vec2::Zero();      // g turned by +90 deg
  double r_t = 0;                // target footprint radius (mm)
  Vec2 wall_point = Vec2::Zero(), wall_n = Vec2::Zero();  // warehouse wall: a point and its normal
  Occluder occl;
  // The final render (objects, occluder, background), when the visibility
  // check already made it (no occluder); annotate() then reuses it.
  std::optional<RenderOutput> full;

  const Placed& target() const { return objs[0]; }
  // Objects (and the occluder) that a new footprint must keep clear of.
  std::vector<const Placed*> standing() const;
  std::vector<const Placed*> objects() const;
};

std::array<int, 4> bbox_of(int umin, int vmin, int umax, int vmax);
Polygon transform_footprint(const Polygon& local, double yaw, const Vec2& at);

// What a generator copies to a clone: everything but the renderer.
struct GeneratorState {
  SceneSettings s;
  std::vector<SceneModel> models;           // by obj_id
  std::vector<RestPoses> rest;              // parallel to models
  std::vector<std::vector<Vec3>> hull;      // convex hull vertices per model
  std::vector<double> radius;               // max vertex norm per model
  int target = -1;
  std::vector<int> pool;                    // model indices of the distractor pool (without the target)
  Mesh table_mesh, floor_mesh, wall_mesh;
  Intrinsics K;
  RenderSettings rset;
};

}  // namespace scene_detail

struct SceneGenerator::Impl : scene_detail::GeneratorState {
  using Placed = scene_detail::Placed;
  using AloneStats = scene_detail::AloneStats;
  using Layout = scene_detail::Layout;
  using Vec2 = scene_detail::Vec2;

  std::unique_ptr<DepthRenderer> renderer;
  // With setups: each set-up's layout (or why it has none), made once per
  // generator by setup_layout and copied for every image that shows it.
  struct SetUp {
    bool ok = false;
    Layout layout;
    std::string why;
  };
  std::map<int, SetUp> setups_made;

  explicit Impl(const scene_detail::GeneratorState& state)
      : GeneratorState(state), renderer(std::make_unique<DepthRenderer>(K, rset)) {}

  double half_fov_min() const {
    return std::min(std::atan(0.5 * K.width / K.fx), std::atan(0.5 * K.height / K.fy));
  }
  bool warehouse() const { return s.scenario == Scenario::warehouse; }
  double gap() const { return warehouse() ? s.warehouse.gap_mm : s.table.gap_mm; }

  // Places model `mi` in rest pose `ri` with yaw at ground point xy.
  Placed on_ground(int mi, int ri, double yaw, const Vec2& xy) const;
  // Places model `mi` rotated by R (model -> world) with its lowest point on
  // the ground at xy.
  Placed on_ground_rotated(int mi, const Mat3& R, const Vec2& xy) const;

  // One attempt at image im_id (false with `why`).
  bool generate_attempt(int im_id, int attempt, GeneratedImage& img, std::string& why);
  // With setups: set-up k's objects (target first, background), drawn from
  // their own stream until a reference camera accepts them as an image
  // would; false with `why` after max_attempts.
  bool setup_layout(int k, Layout& L, std::string& why);
  // With setups: image im_id's camera around its set-up (false with `why`).
  bool generate_setup_attempt(int im_id, int attempt, GeneratedImage& img, std::string& why);

  // The layout steps of an attempt, in their order of random draws (false
  // with `why` when the layout is rejected).
  void place_target(Rng& rng, Layout& L) const;
  bool place_camera(Rng& rng, Layout& L, GeneratedImage& img, std::string& why) const;
  void place_background(Rng& rng, Layout& L) const;
  Placed wall_at(const Layout& L, double bottom) const;
  bool place_occluder(Rng& rng, Layout& L, std::string& why) const;
  bool place_distractors(Rng& rng, Layout& L, std::string& why) const;
  // Whether ground point q lies on the table (at least table_margin inside
  // its edges) or in front of the warehouse wall (gap_mm).
  bool on_ground_area(const Layout& L, const Vec2& q, double table_margin) const;
  // Whether a footprint fits: on the ground area, apart from `others`, and
  // far enough from the camera.
  bool fits(const Layout& L, const Placed& p, const std::vector<const Placed*>& others) const;
  // Whether p keeps the camera clearances (camera.*clearance_mm) from L's camera.
  bool clear_of_camera(const Layout& L, const Placed& p) const;

  // The rendering steps.
  // The render items of a layout's objects (labels 0..n-1), `extras`
  // (occluder label) and, with `background`, bg (background label).
  static std::vector<RenderItem> render_items(const std::vector<const Placed*>& objs,
                                              const std::vector<const Placed*>& extras, const Pose& T_cam_world,
                                              bool background, const std::vector<Placed>& bg);
  // Projected bounding box of the object's hull (pixels); false if some
  // vertex is behind the near plane (never for accepted layouts).
  bool project_bbox(const Placed& p, const Pose& T_cam_world, double& umin, double& umax, double& vmin,
                    double& vmax) const;
  // Silhouette of one object alone. When it crosses the image border, the
  // part outside is rendered too (tiles of the image size with shifted
  // principal points), so px_count_all counts the whole silhouette, as BOP's
  // calc_gt_info does on an enlarged canvas. Returns false if the object lies
  // entirely outside the image.
  bool alone(const Placed& p, const Pose& T_cam_world, AloneStats& st);
  // The target's visible fraction with the objects and `extras`.
  double target_visib(const Layout& L, const AloneStats& target_alone, const std::vector<const Placed*>& extras);
  // Without an occluder: the same fraction from the final render (kept in
  // L.full), where it must be the same number (see the .cpp); false when
  // it cannot be told from it.
  bool target_visib_from_final(Layout& L, const AloneStats& target_alone, double& visib);
  // Without an occluder: the target must be visible enough. With one: its
  // height is searched so that the target's visible fraction meets the goal.
  bool reach_visibility(Layout& L, const AloneStats& target_alone, std::string& why);
  bool search_occluder_height(Layout& L, const AloneStats& target_alone, double v0, std::string& why);
  void set_occluder_height(Layout& L, double h) const;
  // Silhouettes of the objects alone (target's given); present[i] = 0 for
  // objects entirely outside the image.
  void silhouettes(const Layout& L, const AloneStats& target_alone, std::vector<AloneStats>& alone_stats,
                   std::vector<char>& present);
  // Final render with the background, ground truth, labels, noise, gt_info.
  void annotate(Layout& L, const AloneStats& target_alone, int im_id, GeneratedImage& img);
};

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

// The layout steps of an attempt: target, camera, background, occluder
// footprint and other objects.

// 1. Target at the origin.
void SceneGenerator::Impl::place_target(Rng& rng, Layout& L) const {
  if (s.target_free_probability > 0 && rng.uniform() < s.target_free_probability) {
    const Mat3 R = random_rotation(rng);  // uniform: yaw included
    L.objs.push_back(on_ground_rotated(target, R, Vec2::Zero()));
    return;
  }
  const int ri = sample_rest_pose(rest[target], s.target_upright_probability, rng);
  const double yaw = rng.uniform(0, 2 * M_PI);
  Placed p = on_ground(target, ri, yaw, Vec2::Zero());
  if (s.target_tilt_deg > 0) {  // the rest pose leaned about a horizontal axis, on its lowest point
    const double axis_az = rng.uniform(0, 2 * M_PI);
    const double tilt = rng.uniform(0, s.target_tilt_deg) * M_PI / 180.0;
    p = on_ground_rotated(target, axis_angle(Vec3(std::cos(axis_az), std::sin(axis_az), 0), tilt) * p.T_world_model.R,
                          Vec2::Zero());
  }
  L.objs.push_back(std::move(p));
}

// 2. Camera: distance, elevation and azimuth, looking at the target's centre
// shifted in the image plane by up to look_jitter of the half view.
bool SceneGenerator::Impl::place_camera(Rng& rng, Layout& L, GeneratedImage& img, std::string& why) const {
  const Placed& tgt = L.target();
  const double dist = rng.uniform(s.camera.distance_mm.lo, s.camera.distance_mm.hi);
  const double elev = rng.uniform(s.camera.elevation_deg.lo, s.camera.elevation_deg.hi) * M_PI / 180.0;
  const double az = rng.uniform(0, 2 * M_PI);
  const Vec3 look(0, 0, 0.5 * tgt.height);
  const Vec3 eye0 = look + dist * Vec3(std::cos(elev) * std::cos(az), std::cos(elev) * std::sin(az), std::sin(elev));
  Pose T_world_cam = look_at(eye0, look, Vec3::UnitZ());
  const double jitter = s.camera.look_jitter * dist * std::tan(half_fov_min());
  T_world_cam.t += rng.uniform(-jitter, jitter) * T_world_cam.R.col(0) +
                   rng.uniform(-jitter, jitter) * T_world_cam.R.col(1);
  L.dist = dist;
  L.eye = T_world_cam.t;
  L.T_world_cam = T_world_cam;
  L.T_cam_world = T_world_cam.inverse();
  img.camera_distance_mm = dist;
  img.camera_elevation_deg = elev * 180.0 / M_PI;
  img.camera_azimuth_deg = az * 180.0 / M_PI;
  img.T_world_cam = T_world_cam;
  if (L.eye.z() <= 0) {
    why = "camera below the ground";
    return false;
  }
  // Ground direction towards the camera and its perpendicular.
  Vec2 g(L.eye.x(), L.eye.y());
  if (g.norm() < 1e-6) g = Vec2(std::cos(az), std::sin(az));
  g.normalize();
  L.g = g;
  L.perp = Vec2(-g.y(), g.x());
  L.r_t = 0;
  for (const auto& q : tgt.footprint) L.r_t = std::max(L.r_t, q.norm());
  return true;
}

// A wall facing the camera (normal L.wall_n, horizontal) whose face passes
// through L.wall_point, from height `bottom` up.
Placed SceneGenerator::Impl::wall_at(const Layout& L, double bottom) const {
  const WarehouseSettings& w = s.warehouse;
  Placed wall;
  wall.mesh = &wall_mesh;
  const double yaw = std::atan2(L.wall_n.y(), L.wall_n.x()) - M_PI / 2;  // box y axis along wall_n
  wall.T_world_model.R = axis_angle(Vec3::UnitZ(), yaw);
  const Vec2 c = L.wall_point - L.wall_n * (0.5 * w.wall_thickness_mm);
  wall.T_world_model.t = Vec3(c.x(), c.y(), bottom + 0.5 * w.wall_height_mm);
  return wall;
}

// 3. Table under everything, and (table.floor_drop_mm, wall_distance_mm) a
// room around it: a floor below and a wall behind the table as seen from
// the camera; warehouse: a floor and (warehouse.wall) a wall behind the
// target. Only a room's wall draws from the stream (default sets keep their
// images).
void SceneGenerator::Impl::place_background(Rng& rng, Layout& L) const {
  L.wall_point = Vec2::Zero();
  L.wall_n = L.g;
  if (!warehouse()) {
    const TableSettings& t = s.table;
    Placed table;
    table.mesh = &table_mesh;
    table.T_world_model.t = Vec3(0, 0, -0.5 * t.thickness_mm);
    L.bg.push_back(table);
    if (t.floor_drop_mm > 0) {
      Placed floor;
      floor.mesh = &floor_mesh;
      floor.T_world_model.t = Vec3(0, 0, -t.floor_drop_mm - 0.5 * s.warehouse.floor_thickness_mm);
      L.bg.push_back(floor);
    }
    if (t.wall_distance_mm.hi > 0) {
      double far = 0;  // the table's farthest corner from the target, away from the camera
      for (const double x : {-0.5, 0.5})
        for (const double y : {-0.5, 0.5}) far = std::max(far, -L.g.dot(Vec2(x, y) * t.size_mm));
      L.wall_point = -L.g * (far + rng.uniform(t.wall_distance_mm.lo, t.wall_distance_mm.hi));
      L.bg.push_back(wall_at(L, -t.floor_drop_mm));
    }
    return;
  }
  const WarehouseSettings& w = s.warehouse;
  const double wd = L.r_t + rng.uniform(w.wall_distance_mm.lo, w.wall_distance_mm.hi);
  const double wyaw = rng.uniform(-w.wall_yaw_deg, w.wall_yaw_deg) * M_PI / 180.0;
  L.wall_n = Eigen::Rotation2Dd(wyaw) * L.g;
  L.wall_point = -L.g * wd;
  Placed floor;
  floor.mesh = &floor_mesh;
  floor.T_world_model.t = Vec3(0, 0, -0.5 * w.floor_thickness_mm);
  L.bg.push_back(floor);
  if (!w.wall) return;  // the floor alone (on_ground_area: no wall bounds it)
  L.bg.push_back(wall_at(L, 0.0));
}

bool SceneGenerator::Impl::on_ground_area(const Layout& L, const Vec2& q, double table_margin) const {
  if (warehouse()) return !s.warehouse.wall || !((q - L.wall_point).dot(L.wall_n) < gap());
  return !(std::abs(q.x()) > 0.5 * s.table.size_mm - table_margin ||
           std::abs(q.y()) > 0.5 * s.table.size_mm - table_margin);
}

bool SceneGenerator::Impl::fits(const Layout& L, const Placed& p, const std::vector<const Placed*>& others) const {
  const double gap = this->gap();
  for (const auto& q : p.footprint)
    if (!on_ground_area(L, q, gap)) return false;
  for (const Placed* o : others)
    if (convex_polygons_overlap(p.footprint, o->footprint, gap)) return false;
  return clear_of_camera(L, p);
}

bool SceneGenerator::Impl::clear_of_camera(const Layout& L, const Placed& p) const {
  const Vec3 centre = p.T_world_model.t + p.T_world_model.R * Vec3::Zero();
  if ((L.T_cam_world * centre).z() - p.radius < rset.near_mm + s.camera.depth_clearance_mm) return false;
  if ((centre - L.eye).norm() < p.radius + rset.near_mm + s.camera.clearance_mm) return false;
  return true;
}

// 4. Occluder footprint between camera and target (occluded images only);
// its height is searched once everything is placed.
bool SceneGenerator::Impl::place_occluder(Rng& rng, Layout& L, std::string& why) const {
  const OcclusionSettings& o = s.occlusion;
  Occluder& oc = L.occl;
  oc.on = o.enabled && rng.bernoulli(o.probability);
  oc.goal = oc.on ? rng.uniform(o.visib_fract.lo, o.visib_fract.hi) : 0.0;
  if (!oc.on) return true;
  const double r_t = L.r_t;
  oc.box = rng.bernoulli(o.box_probability);
  double half_depth;
  if (oc.box) {
    oc.w = rng.uniform(o.box_width.lo, o.box_width.hi) * 2 * r_t;
    oc.d = rng.uniform(o.box_depth_mm.lo, o.box_depth_mm.hi);
    half_depth = 0.5 * oc.d;
  } else {
    oc.r = std::max(o.cylinder_min_radius_mm, rng.uniform(o.cylinder_radius.lo, o.cylinder_radius.hi) * r_t);
    half_depth = oc.r;
  }
  const double lateral = rng.uniform(o.lateral_offset.lo, o.lateral_offset.hi) * r_t;
  const double along = r_t + half_depth + gap() + rng.uniform(o.extra_distance.lo, o.extra_distance.hi) * r_t;
  const Vec2 c = L.g * along + L.perp * lateral;
  const double yaw = std::atan2(L.perp.y(), L.perp.x());  // box x axis (width) along perp
  Polygon local;
  if (oc.box) {
    local = {{-oc.w / 2, -oc.d / 2}, {oc.w / 2, -oc.d / 2}, {oc.w / 2, oc.d / 2}, {-oc.w / 2, oc.d / 2}};
  } else {
    const int n = o.footprint_sides;
    for (int k = 0; k < n; ++k)
      local.emplace_back(oc.r * std::cos(2 * M_PI * k / n), oc.r * std::sin(2 * M_PI * k / n));
  }
  oc.placed.footprint = transform_footprint(local, yaw, c);
  oc.placed.T_world_model.R = axis_angle(Vec3::UnitZ(), yaw);
  oc.placed.T_world_model.t = Vec3(c.x(), c.y(), 0);
  // Height hiding the whole target (line from the eye over the target's
  // top, at the occluder's far side), with a margin; below the camera.
  const Vec3& eye = L.eye;
  const double tgt_h = L.target().height;
  const double D = Vec2(eye.x(), eye.y()).norm();
  const double x = std::max(0.0, along - half_depth);
  double h = tgt_h + (eye.z() - tgt_h) * std::min(1.0, x / std::max(D, 1e-6));
  oc.hmax = std::min(o.height_factor * h + o.height_margin_mm, eye.z() - o.camera_headroom_mm);
  if (oc.hmax <= o.min_height_mm) {
    why = "no room for an occluder";
    return false;
  }
  oc.placed.radius = std::sqrt(std::pow(oc.box ? 0.5 * std::hypot(oc.w, oc.d) : oc.r, 2) + oc.hmax * oc.hmax);
  // Camera clearance for the tallest occluder.
  if ((Vec3(c.x(), c.y(), 0.5 * oc.hmax) - eye).norm() < oc.placed.radius + rset.near_mm + s.camera.clearance_mm) {
    why = "occluder too close to the camera";
    return false;
  }
  for (const auto& q : oc.placed.footprint)
    if (!on_ground_area(L, q, 0.0)) {
      why = "occluder does not fit";
      return false;
    }
  return true;
}

// 5. Other objects, scattered around the target (a disc as wide as the view
// at the target's distance) with their origin inside the image.
bool SceneGenerator::Impl::place_distractors(Rng& rng, Layout& L, std::string& why) const {
  const DistractorSettings& ds = s.distractors;
  double spread = std::max(ds.spread_min_radii * L.r_t, L.dist * std::tan(half_fov_min()));
  if (ds.spread_max_radii > 0) spread = std::min(spread, ds.spread_max_radii * L.r_t);
  const int n_other = pool.empty() ? 0 : rng.uniform_int(ds.min_count, ds.max_count);
  const double m = ds.image_margin;
  for (int k = 0; k < n_other; ++k) {
    const int mi = pool[rng.uniform_int(0, static_cast<int>(pool.size()) - 1)];
    const int ri = sample_rest_pose(rest[mi], ds.upright_probability, rng);
    const std::vector<const Placed*> others = L.standing();
    bool ok = false;
    for (int tries = 0; tries < ds.placement_tries && !ok; ++tries) {
      const double r = spread * std::sqrt(rng.uniform());
      const double phi = rng.uniform(0, 2 * M_PI);
      const double yaw = rng.uniform(0, 2 * M_PI);
      Placed p = on_ground(mi, ri, yaw, Vec2(r * std::cos(phi), r * std::sin(phi)));
      const Vec3 c = L.T_cam_world * (p.T_world_model.t + Vec3(0, 0, 0));
      if (c.z() <= rset.near_mm) continue;
      const auto uv = K.project(c);
      if (uv.x() < -m * K.width || uv.x() > (1 + m) * K.width || uv.y() < -m * K.height ||
          uv.y() > (1 + m) * K.height)
        continue;
      if (!fits(L, p, others)) continue;
      L.objs.push_back(std::move(p));
      ok = true;
    }
    if (!ok) {
      why = "could not place " + std::to_string(n_other) + " other objects";
      return false;
    }
  }
  return true;
}

// The rendering steps of an attempt: silhouettes of single objects, the
// target's visibility and the occluder height search, and the final
// annotated image.

std::vector<RenderItem> SceneGenerator::Impl::render_items(const std::vector<const Placed*>& objs,
                                                          const std::vector<const Placed*>& extras,
                                                          const Pose& T_cam_world, bool background,
                                                          const std::vector<Placed>& bg) {
  std::vector<RenderItem> items;
  for (size_t i = 0; i < objs.size(); ++i)
    items.push_back({objs[i]->mesh, T_cam_world * objs[i]->T_world_model, static_cast<int>(i)});
  for (const Placed* e : extras) items.push_back({e->mesh, T_cam_world * e->T_world_model, kOccluderLabel});
  if (background)
    for (const Placed& b : bg) items.push_back({b.mesh, T_cam_world * b.T_world_model, kBackgroundLabel});
  return items;
}

bool SceneGenerator::Impl::project_bbox(const Placed& p, const Pose& T_cam_world, double& umin, double& umax,
                                        double& vmin, double& vmax) const {
  const Pose T = T_cam_world * p.T_world_model;
  umin = vmin = 1e300, umax = vmax = -1e300;
  for (const auto& v : hull[p.model]) {
    const Vec3 c = T * v;
    if (c.z() <= rset.near_mm) return false;
    const auto uv = K.project(c);
    umin = std::min(umin, uv.x()), umax = std::max(umax, uv.x());
    vmin = std::min(vmin, uv.y()), vmax = std::max(vmax, uv.y());
  }
  return true;
}

bool SceneGenerator::Impl::alone(const Placed& p, const Pose& T_cam_world, AloneStats& st) {
  const Pose T = T_cam_world * p.T_world_model;
  double umin, umax, vmin, vmax;
  if (!project_bbox(p, T_cam_world, umin, umax, vmin, vmax)) return false;
  const int W = K.width, H = K.height;
  if (umax < -0.5 || vmax < -0.5 || umin > W - 0.5 || vmin > H - 0.5) return false;
  st = AloneStats();
  const std::vector<RenderItem> items{{p.mesh, T, 0}};
  int bu0 = 1 << 30, bv0 = 1 << 30, bu1 = -(1 << 30), bv1 = -(1 << 30);
  // Counts the silhouette pixels of a render whose pixel (0, 0) is (u0, v0)
  // of the virtual image, up to (ub, vb).
  auto scan = [&](const std::vector<int32_t>& labels, int u0, int v0, int ub, int vb) {
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        if (labels[static_cast<size_t>(y) * W + x] != 0) continue;
        const int u = x + u0, v = y + v0;
        if (u > ub || v > vb) continue;
        ++st.px_all;
        if (u >= 0 && v >= 0 && u < W && v < H) st.pixels.push_back(v * W + u);
        bu0 = std::min(bu0, u), bu1 = std::max(bu1, u), bv0 = std::min(bv0, v), bv1 = std::max(bv1, v);
      }
  };
  const bool inside = umin >= -0.5 && vmin >= -0.5 && umax <= W - 0.5 && vmax <= H - 0.5;
  if (inside) {
    scan(renderer->render_labels(items, /*overlap=*/false), 0, 0, INT_MAX, INT_MAX);
  } else {
    st.tiled = true;
    // Pixels whose centres can be covered: [ceil(min - 0.5), floor(max + 0.5)],
    // limited to 3 image sizes around the image.
    const int ua = std::max(-W, static_cast<int>(std::floor(umin)) - 1);
    const int ub = std::min(2 * W - 1, static_cast<int>(std::ceil(umax)) + 1);
    const int va = std::max(-H, static_cast<int>(std::floor(vmin)) - 1);
    const int vb = std::min(2 * H - 1, static_cast<int>(std::ceil(vmax)) + 1);
    for (int v0 = va; v0 <= vb; v0 += H)
      for (int u0 = ua; u0 <= ub; u0 += W) {
        Intrinsics Kt = K;
        Kt.cx -= u0;
        Kt.cy -= v0;
        renderer->set_intrinsics(Kt);
        const std::vector<int32_t> labels = renderer->render_labels(items, /*overlap=*/false);
        renderer->set_intrinsics(K);
        // Tiles overlap the requested range only where they extend past
        // ub / vb: count each pixel once.
        scan(labels, u0, v0, ub, vb);
      }
    std::sort(st.pixels.begin(), st.pixels.end());
  }
  st.bbox = bbox_of(bu0, bv0, bu1, bv1);
  return true;
}

double SceneGenerator::Impl::target_visib(const Layout& L, const AloneStats& target_alone,
                                          const std::vector<const Placed*>& extras) {
  const std::vector<int32_t> labels =
      renderer->render_labels(render_items(L.objects(), extras, L.T_cam_world, false, L.bg));
  int n = 0;
  for (int32_t l : labels) n += (l == 0);
  return static_cast<double>(n) / target_alone.px_all;
}

void SceneGenerator::Impl::set_occluder_height(Layout& L, double h) const {
  Occluder& oc = L.occl;
  oc.mesh = oc.box ? make_box(oc.w, oc.d, h) : make_cylinder(oc.r, h, s.occlusion.cylinder_segments);
  oc.placed.mesh = &oc.mesh;
  oc.placed.T_world_model.t.z() = 0.5 * h;
  oc.placed.height = h;
}

// The final render adds the background after the objects, and a fragment
// replaces one only when strictly nearer: so each pixel's final label is its
// label among the objects alone, or the background's. The target's pixels
// among the objects alone are then its final pixels plus those of its own
// silhouette that the background covers in the final render. Where the
// background covers none of the silhouette (a table is never in front of
// what stands on it), the two counts are equal. The silhouette must come
// from a render with the image's own K (not tiles) to have the same pixels.
bool SceneGenerator::Impl::target_visib_from_final(Layout& L, const AloneStats& target_alone, double& visib) {
  if (target_alone.tiled) return false;
  L.full = renderer->render(render_items(L.objects(), {}, L.T_cam_world, true, L.bg));
  const std::vector<int32_t>& labels = L.full->labels;
  for (int p : target_alone.pixels)
    if (labels[static_cast<size_t>(p)] == kBackgroundLabel) return false;
  int n = 0;
  for (int32_t l : labels) n += (l == 0);
  visib = static_cast<double>(n) / target_alone.px_all;
  return true;
}

bool SceneGenerator::Impl::reach_visibility(Layout& L, const AloneStats& target_alone, std::string& why) {
  L.occl.height = 0;
  if (!L.occl.on) {
    double v;
    if (!target_visib_from_final(L, target_alone, v)) v = target_visib(L, target_alone, {});
    if (v < s.min_target_visib) {
      why = "target not visible enough";
      return false;
    }
    return true;
  }
  const double v0 = target_visib(L, target_alone, {});
  if (v0 < s.occlusion.visib_fract.lo) {
    why = "target too occluded before the occluder";
    return false;
  }
  return search_occluder_height(L, target_alone, v0, why);
}

// Visible fraction falls as the occluder grows: find the height where it
// meets the goal by regula falsi (Illinois variant) on [0, hmax].
bool SceneGenerator::Impl::search_occluder_height(Layout& L, const AloneStats& target_alone, double v0,
                                                  std::string& why) {
  const OcclusionSettings& o = s.occlusion;
  Occluder& oc = L.occl;
  const double goal = oc.goal;
  double a = 0, fa = v0 - goal, b = oc.hmax, best_h = -1, best_err = 1e300;
  set_occluder_height(L, b);
  const double vmax = target_visib(L, target_alone, {&oc.placed});
  double fb = vmax - goal;
  if (vmax > o.visib_fract.hi) {
    why = "occluder too small";
    return false;
  }
  auto consider = [&](double h, double v) {
    if (v >= o.visib_fract.lo && v <= o.visib_fract.hi && std::abs(v - goal) < best_err)
      best_h = h, best_err = std::abs(v - goal);
  };
  consider(b, vmax);
  if (fa <= 0) consider(o.token_height * oc.hmax, v0);  // already occluded enough: a token occluder
  int side = 0;
  for (int it = 0; it < o.search_iterations && best_err > o.search_tolerance && fa > 0 && fb < 0; ++it) {
    double c = b - fb * (b - a) / (fb - fa);
    if (!(c > a && c < b)) c = 0.5 * (a + b);
    set_occluder_height(L, c);
    const double fc = target_visib(L, target_alone, {&oc.placed}) - goal;
    consider(c, fc + goal);
    if (fc > 0) {
      a = c, fa = fc;
      if (side == -1) fb *= 0.5;
      side = -1;
    } else {
      b = c, fb = fc;
      if (side == 1) fa *= 0.5;
      side = 1;
    }
  }
  if (best_h < 0) {
    why = "occluded fraction not reached";
    return false;
  }
  set_occluder_height(L, best_h);
  oc.height = best_h;
  return true;
}

// Objects inside the image whose projected boxes are disjoint cannot
// overlap: they are rendered together (same pixels as one by one, fewer
// renders).
void SceneGenerator::Impl::silhouettes(const Layout& L, const AloneStats& target_alone,
                                       std::vector<AloneStats>& alone_stats, std::vector<char>& present) {
  const std::vector<Placed>& objs = L.objs;
  const int W = K.width, H = K.height;
  alone_stats.assign(objs.size(), AloneStats());
  present.assign(objs.size(), 0);
  alone_stats[0] = target_alone;
  present[0] = 1;
  std::vector<std::vector<int>> groups;
  std::vector<std::vector<Eigen::AlignedBox2d>> member_boxes;
  for (size_t i = 1; i < objs.size(); ++i) {
    double umin, umax, vmin, vmax;
    if (!project_bbox(objs[i], L.T_cam_world, umin, umax, vmin, vmax)) continue;
    if (umax < -0.5 || vmax < -0.5 || umin > W - 0.5 || vmin > H - 0.5) continue;  // outside the image
    if (!(umin >= -0.5 && vmin >= -0.5 && umax <= W - 0.5 && vmax <= H - 0.5)) {
      present[i] = alone(objs[i], L.T_cam_world, alone_stats[i]);  // crosses the border: tiles
      continue;
    }
    const Eigen::AlignedBox2d box(Eigen::Vector2d(umin - 1, vmin - 1), Eigen::Vector2d(umax + 1, vmax + 1));
    size_t g = 0;
    for (; g < groups.size(); ++g)
      if (std::none_of(member_boxes[g].begin(), member_boxes[g].end(),
                       [&](const Eigen::AlignedBox2d& b) { return b.intersects(box); }))
        break;
    if (g == groups.size()) {
      groups.emplace_back();
      member_boxes.emplace_back();
    }
    groups[g].push_back(static_cast<int>(i));
    member_boxes[g].push_back(box);
  }
  for (const auto& group : groups) {
    std::vector<RenderItem> items;
    for (size_t j = 0; j < group.size(); ++j)
      items.push_back({objs[group[j]].mesh, L.T_cam_world * objs[group[j]].T_world_model, static_cast<int>(j)});
    const std::vector<int32_t> labels = renderer->render_labels(items, /*overlap=*/false);
    std::vector<std::array<int, 4>> bb(group.size(), {{W, H, -1, -1}});
    for (int v = 0; v < H; ++v)
      for (int u = 0; u < W; ++u) {
        const int32_t l = labels[static_cast<size_t>(v) * W + u];
        if (l < 0 || l >= static_cast<int32_t>(group.size())) continue;
        AloneStats& st = alone_stats[group[l]];
        ++st.px_all;
        st.pixels.push_back(v * W + u);
        auto& b = bb[l];
        b[0] = std::min(b[0], u), b[1] = std::min(b[1], v), b[2] = std::max(b[2], u), b[3] = std::max(b[3], v);
      }
    for (size_t j = 0; j < group.size(); ++j) {
      alone_stats[group[j]].bbox = bbox_of(bb[j][0], bb[j][1], bb[j][2], bb[j][3]);
      present[group[j]] = 1;
    }
  }
}

namespace {

// The visible pixels of one label: count and box (u0, v0, u1, v1).
struct Visible {
  int count = 0;
  std::array<int, 4> box{};
};

// Visible pixels of labels 0..n-1, in one pass over the final labels.
std::vector<Visible> visible_of(const std::vector<int>& labels, int n, int W, int H) {
  std::vector<Visible> vis(static_cast<size_t>(n));
  for (auto& v : vis) v.box = {{W, H, -1, -1}};
  for (int v = 0; v < H; ++v)
    for (int u = 0; u < W; ++u) {
      const int l = labels[static_cast<size_t>(v) * W + u];
      if (l < 0 || l >= n) continue;
      Visible& x = vis[static_cast<size_t>(l)];
      ++x.count;
      x.box[0] = std::min(x.box[0], u), x.box[1] = std::min(x.box[1], v);
      x.box[2] = std::max(x.box[2], u), x.box[3] = std::max(x.box[3], v);
    }
  return vis;
}

// BOP's gt_info of an annotated object from its silhouette, its visible
// pixels and the final depth.
GtInfo gt_info_of(const AloneStats& st, const Visible& vis, const GeneratedImage& img) {
  GtInfo gi;
  gi.px_count_all = st.px_all;
  gi.bbox_obj = st.bbox;
  int valid = 0;
  for (int p : st.pixels) valid += img.depth.z[p] > 0.f;
  gi.px_count_valid = valid;
  gi.px_count_visib = vis.count;
  gi.bbox_visib = bbox_of(vis.box[0], vis.box[1], vis.box[2], vis.box[3]);
  gi.visib_fract = gi.px_count_all > 0 ? static_cast<double>(vis.count) / gi.px_count_all : 0.0;
  return gi;
}

}  // namespace

void SceneGenerator::Impl::annotate(Layout& L, const AloneStats& target_alone, int im_id,
                                    GeneratedImage& img) {
  const std::vector<Placed>& objs = L.objs;
  std::vector<const Placed*> extras;
  if (L.occl.on) extras.push_back(&L.occl.placed);
  RenderOutput full =
      L.full ? std::move(*L.full) : renderer->render(render_items(L.objects(), extras, L.T_cam_world, true, L.bg));
  const int W = K.width, H = K.height;
  const size_t npx = static_cast<size_t>(W) * H;

  std::vector<int> remap(objs.size(), -1);
  std::vector<AloneStats> stats;
  img.info = ImageInfo();
  img.info.im_id = im_id;
  img.info.K = K;
  img.info.depth_scale = s.depth_scale;
  img.names.clear();
  std::vector<AloneStats> alone_stats;
  std::vector<char> present;
  silhouettes(L, target_alone, alone_stats, present);
  for (size_t i = 0; i < objs.size(); ++i) {
    if (!present[i]) continue;
    remap[i] = static_cast<int>(stats.size());
    stats.push_back(std::move(alone_stats[i]));
    GtObject gt;
    gt.obj_id = models[objs[i].model].obj_id;
    gt.T_cam_model = L.T_cam_world * objs[i].T_world_model;
    img.info.gt.push_back(gt);
    img.names.push_back(models[objs[i].model].name);
  }
  img.labels.assign(npx, -1);
  for (size_t k = 0; k < npx; ++k) {
    const int32_t l = full.labels[k];
    if (l >= 0 && l < static_cast<int32_t>(objs.size())) img.labels[k] = remap[l];
  }
  // The renderer's labels become the ground-truth indices for the noise
  // models (edges between objects).
  img.depth_clean = full.depth;
  img.depth = full.depth;
  Rng noise_rng(derive_seed(s.seed, {static_cast<uint64_t>(s.scene_id), static_cast<uint64_t>(im_id), kNoiseStream}));
  apply_noise(img.depth, full, s.sensor, s.noise, noise_rng);
  const double zmax_png = 65535.0 * s.depth_scale;
  for (auto& z : img.depth.z)
    if (!(z > 0.f) || !std::isfinite(z) || z > zmax_png) z = 0.f;
  const std::vector<Visible> vis = visible_of(img.labels, static_cast<int>(stats.size()), W, H);
  for (size_t k = 0; k < stats.size(); ++k) img.info.gt_info.push_back(gt_info_of(stats[k], vis[k], img));
  if (s.has_stated_intrinsics) {  // the files state other intrinsics: the poses as they read them
    for (auto& gt : img.info.gt) gt.T_cam_model = stated_pose(gt.T_cam_model, K, s.stated_intrinsics);
    img.info.K = s.stated_intrinsics;
  }
}

}  // namespace pb
