#include "scenes/generator.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <limits>
#include <mutex>
#include <nlohmann/json.hpp>
#include <set>
#include <thread>

#include "core/error.h"
#include "core/random.h"
#include "core/rotation.h"
#include "core/timer.h"
#include "io/mesh_io.h"
#include "io/png.h"
#include "models/procedural.h"
#include "models/registry.h"
#include "render/renderer.h"
#include "render/sensor.h"
#include "scenes/rest_poses.h"

namespace pb {

namespace fs = std::filesystem;

namespace {

constexpr uint64_t kModelStream = 0x6d6f64656cull;  // "model"
constexpr int kOccluderLabel = 1000;
constexpr int kBackgroundLabel = 2000;

uint64_t fnv1a(const std::string& s) {
  uint64_t h = 1469598103934665603ull;
  for (unsigned char c : s) h = (h ^ c) * 1099511628211ull;
  return h;
}

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
};

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

}  // namespace

struct SceneGenerator::Impl {
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
  std::unique_ptr<DepthRenderer> renderer;

  double half_fov_min() const {
    return std::min(std::atan(0.5 * K.width / K.fx), std::atan(0.5 * K.height / K.fy));
  }

  // Places model `mi` in rest pose `ri` with yaw at ground point xy.
  Placed on_ground(int mi, int ri, double yaw, const Vec2& xy) const {
    Placed p;
    p.model = mi;
    p.mesh = &models[mi].mesh;
    const Mat3 R = axis_angle(Vec3::UnitZ(), yaw) * rest[mi].poses[ri].R_rest;
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

  // Renders items; GT objects get labels 0..n-1.
  RenderOutput render(DepthRenderer& r, const std::vector<const Placed*>& objs,
                      const std::vector<const Placed*>& extras, const Pose& T_cam_world,
                      bool background, const std::vector<Placed>& bg) {
    std::vector<RenderItem> items;
    for (size_t i = 0; i < objs.size(); ++i)
      items.push_back({objs[i]->mesh, T_cam_world * objs[i]->T_world_model, static_cast<int>(i)});
    for (const Placed* e : extras) items.push_back({e->mesh, T_cam_world * e->T_world_model, kOccluderLabel});
    if (background)
      for (const Placed& b : bg) items.push_back({b.mesh, T_cam_world * b.T_world_model, kBackgroundLabel});
    return r.render(items);
  }

  // Silhouette of one object alone. When it crosses the image border, the
  // part outside is rendered too (tiles of the image size with shifted
  // principal points), so px_count_all counts the whole silhouette, as BOP's
  // calc_gt_info does on an enlarged canvas. Returns false if the object lies
  // entirely outside the image.
  // Projected bounding box of the object's hull (pixels); false if some
  // vertex is behind the near plane (never for accepted layouts).
  bool project_bbox(const Placed& p, const Pose& T_cam_world, double& umin, double& umax, double& vmin,
                    double& vmax) const {
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

  bool alone(const Placed& p, const Pose& T_cam_world, AloneStats& st) {
    const Pose T = T_cam_world * p.T_world_model;
    double umin, umax, vmin, vmax;
    if (!project_bbox(p, T_cam_world, umin, umax, vmin, vmax)) return false;
    const int W = K.width, H = K.height;
    if (umax < -0.5 || vmax < -0.5 || umin > W - 0.5 || vmin > H - 0.5) return false;
    st = AloneStats();
    const std::vector<RenderItem> items{{p.mesh, T, 0}};
    int bu0 = 1 << 30, bv0 = 1 << 30, bu1 = -(1 << 30), bv1 = -(1 << 30);
    auto scan = [&](const RenderOutput& out, int u0, int v0) {
      for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
          if (out.labels[static_cast<size_t>(y) * W + x] != 0) continue;
          const int u = x + u0, v = y + v0;
          ++st.px_all;
          if (u >= 0 && v >= 0 && u < W && v < H) st.pixels.push_back(v * W + u);
          bu0 = std::min(bu0, u), bu1 = std::max(bu1, u), bv0 = std::min(bv0, v), bv1 = std::max(bv1, v);
        }
    };
    const bool inside = umin >= -0.5 && vmin >= -0.5 && umax <= W - 0.5 && vmax <= H - 0.5;
    if (inside) {
      scan(renderer->render(items), 0, 0);
    } else {
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
          const RenderOutput out = renderer->render(items);
          renderer->set_intrinsics(K);
          // Tiles overlap the requested range only where they extend past
          // ub / vb: count each pixel once.
          for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
              if (out.labels[static_cast<size_t>(y) * W + x] != 0) continue;
              const int u = x + u0, v = y + v0;
              if (u > ub || v > vb) continue;
              ++st.px_all;
              if (u >= 0 && v >= 0 && u < W && v < H) st.pixels.push_back(v * W + u);
              bu0 = std::min(bu0, u), bu1 = std::max(bu1, u), bv0 = std::min(bv0, v), bv1 = std::max(bv1, v);
            }
        }
      std::sort(st.pixels.begin(), st.pixels.end());
    }
    st.bbox = bbox_of(bu0, bv0, bu1, bv1);
    return true;
  }

  bool generate_attempt(int im_id, int attempt, GeneratedImage& img, std::string& why);
};

SceneGenerator::SceneGenerator(const SceneSettings& settings) : impl_(std::make_unique<Impl>()) {
  Impl& I = *impl_;
  I.s = settings;
  const SceneSettings& s = I.s;
  const ModelRegistry reg = [&] {
    if (s.registry.empty()) return ModelRegistry::load_default();
    try {
      return ModelRegistry::load(s.registry);
    } catch (const InputError& e) {
      throw InputError(s.config_file, "registry", e.what());
    }
  }();

  // Target first, then the pool, each name once.
  std::vector<std::pair<std::string, std::string>> names{{s.target, "target"}};
  for (const auto& n : s.distractors.pool)
    if (std::none_of(names.begin(), names.end(), [&](const auto& p) { return p.first == n; }))
      names.emplace_back(n, "distractors.pool");
  std::vector<SceneModel> loaded;
  std::vector<RestPoses> rests;
  for (const auto& [name, field] : names) {
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
      Rng r(derive_seed(s.seed, {kModelStream, fnv1a(name)}));
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
    RestPoses rp = compute_rest_poses(m.mesh);
    if (rp.poses.empty())
      throw InputError(s.config_file, field, "model '" + name + "' has no stable rest pose (flat or degenerate mesh)");
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
    if (loaded[i].name == s.target) I.target = static_cast<int>(k);
    I.models.push_back(std::move(loaded[i]));
    I.rest.push_back(std::move(rests[i]));
  }
  for (const auto& n : s.distractors.pool)
    for (size_t k = 0; k < I.models.size(); ++k)
      if (I.models[k].name == n && n != s.target) I.pool.push_back(static_cast<int>(k));
  if (s.distractors.max_count > 0 && I.pool.empty())
    throw InputError(s.config_file, "distractors.pool", "holds only the target; name other models");

  for (size_t k = 0; k < I.models.size(); ++k) {
    const Mesh& mesh = I.models[k].mesh;
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
    I.hull.push_back(std::move(hv));
    I.radius.push_back(r);
  }

  I.table_mesh = make_box(s.table.size_mm, s.table.size_mm, s.table.thickness_mm);
  I.floor_mesh = make_box(40000, 40000, 100);
  I.wall_mesh = make_box(30000, 200, s.warehouse.wall_height_mm);

  I.K = s.sensor.K;
  I.rset.near_mm = 50;
  I.rset.far_mm = 40000;
  I.rset.normals = s.noise.model == "structured_light" || s.noise.model == "tof";
  I.renderer = std::make_unique<DepthRenderer>(I.K, I.rset);
}

SceneGenerator::~SceneGenerator() = default;

SceneGenerator::SceneGenerator() : impl_(std::make_unique<Impl>()) {}

std::unique_ptr<SceneGenerator> SceneGenerator::clone() const {
  std::unique_ptr<SceneGenerator> g(new SceneGenerator());
  Impl& c = *g->impl_;
  const Impl& I = *impl_;
  c.s = I.s;
  c.models = I.models;
  c.rest = I.rest;
  c.hull = I.hull;
  c.radius = I.radius;
  c.target = I.target;
  c.pool = I.pool;
  c.table_mesh = I.table_mesh;
  c.floor_mesh = I.floor_mesh;
  c.wall_mesh = I.wall_mesh;
  c.K = I.K;
  c.rset = I.rset;
  c.renderer = std::make_unique<DepthRenderer>(c.K, c.rset);
  return g;
}

const SceneSettings& SceneGenerator::settings() const { return impl_->s; }
const std::vector<SceneModel>& SceneGenerator::models() const { return impl_->models; }
const SceneModel& SceneGenerator::model(const std::string& name) const {
  for (const auto& m : impl_->models)
    if (m.name == name) return m;
  throw InputError(impl_->s.config_file, "target", "no model '" + name + "' in this scene set");
}

bool SceneGenerator::Impl::generate_attempt(int im_id, int attempt, GeneratedImage& img, std::string& why) {
  Rng rng(derive_seed(s.seed, {static_cast<uint64_t>(s.scene_id), static_cast<uint64_t>(im_id),
                               static_cast<uint64_t>(attempt)}));
  const bool warehouse = s.scenario == Scenario::warehouse;
  const double gap = warehouse ? s.warehouse.gap_mm : s.table.gap_mm;

  // 1. Target at the origin.
  std::vector<Placed> objs;
  objs.reserve(1 + s.distractors.max_count);
  {
    const int ri = sample_rest_pose(rest[target], s.target_upright_probability, rng);
    const double yaw = rng.uniform(0, 2 * M_PI);
    objs.push_back(on_ground(target, ri, yaw, Vec2::Zero()));
  }
  const Placed& tgt = objs[0];

  // 2. Camera.
  const double dist = rng.uniform(s.camera.distance_mm.lo, s.camera.distance_mm.hi);
  const double elev = rng.uniform(s.camera.elevation_deg.lo, s.camera.elevation_deg.hi) * M_PI / 180.0;
  const double az = rng.uniform(0, 2 * M_PI);
  const Vec3 look(0, 0, 0.5 * tgt.height);
  const Vec3 eye0 = look + dist * Vec3(std::cos(elev) * std::cos(az), std::cos(elev) * std::sin(az), std::sin(elev));
  Pose T_world_cam = look_at(eye0, look, Vec3::UnitZ());
  const double jitter = s.camera.look_jitter * dist * std::tan(half_fov_min());
  T_world_cam.t += rng.uniform(-jitter, jitter) * T_world_cam.R.col(0) +
                   rng.uniform(-jitter, jitter) * T_world_cam.R.col(1);
  const Vec3 eye = T_world_cam.t;
  const Pose T_cam_world = T_world_cam.inverse();
  img.camera_distance_mm = dist;
  img.camera_elevation_deg = elev * 180.0 / M_PI;
  img.camera_azimuth_deg = az * 180.0 / M_PI;
  img.T_world_cam = T_world_cam;
  if (eye.z() <= 0) {
    why = "camera below the ground";
    return false;
  }

  // Ground direction towards the camera and its perpendicular.
  Vec2 g(eye.x(), eye.y());
  if (g.norm() < 1e-6) g = Vec2(std::cos(az), std::sin(az));
  g.normalize();
  const Vec2 perp(-g.y(), g.x());
  double r_t = 0;
  for (const auto& q : tgt.footprint) r_t = std::max(r_t, q.norm());

  // Wall (warehouse): behind the target as seen from the camera.
  std::vector<Placed> bg;
  Vec2 wall_point = Vec2::Zero(), wall_n = g;
  if (warehouse) {
    const double wd = r_t + rng.uniform(s.warehouse.wall_distance_mm.lo, s.warehouse.wall_distance_mm.hi);
    const double wyaw = rng.uniform(-15.0, 15.0) * M_PI / 180.0;
    wall_n = Eigen::Rotation2Dd(wyaw) * g;
    wall_point = -g * wd;
    Placed floor;
    floor.mesh = &floor_mesh;
    floor.T_world_model.t = Vec3(0, 0, -50);
    bg.push_back(floor);
    Placed wall;
    wall.mesh = &wall_mesh;
    const double yaw = std::atan2(wall_n.y(), wall_n.x()) - M_PI / 2;  // box y axis along wall_n
    wall.T_world_model.R = axis_angle(Vec3::UnitZ(), yaw);
    const Vec2 c = wall_point - wall_n * 100.0;
    wall.T_world_model.t = Vec3(c.x(), c.y(), 0.5 * s.warehouse.wall_height_mm);
    bg.push_back(wall);
  } else {
    Placed table;
    table.mesh = &table_mesh;
    table.T_world_model.t = Vec3(0, 0, -0.5 * s.table.thickness_mm);
    bg.push_back(table);
  }

  // Whether a footprint fits: inside the table / in front of the wall, apart
  // from the others, and far enough from the camera.
  auto fits = [&](const Placed& p, const std::vector<const Placed*>& others) {
    for (const auto& q : p.footprint) {
      if (!warehouse && (std::abs(q.x()) > 0.5 * s.table.size_mm - gap || std::abs(q.y()) > 0.5 * s.table.size_mm - gap))
        return false;
      if (warehouse && (q - wall_point).dot(wall_n) < gap) return false;
    }
    for (const Placed* o : others)
      if (convex_polygons_overlap(p.footprint, o->footprint, gap)) return false;
    const Vec3 centre = p.T_world_model.t + p.T_world_model.R * Vec3::Zero();
    if ((T_cam_world * centre).z() - p.radius < rset.near_mm + 20) return false;
    if ((centre - eye).norm() < p.radius + rset.near_mm + 50) return false;
    return true;
  };
  if (!fits(tgt, {})) {
    why = "target does not fit (camera too close)";
    return false;
  }

  // 3. Occluder footprint (its height is searched once everything is placed).
  const bool occluded = s.occlusion.enabled && rng.bernoulli(s.occlusion.probability);
  const double goal = occluded ? rng.uniform(s.occlusion.visib_fract.lo, s.occlusion.visib_fract.hi) : 0.0;
  Placed occl;
  Mesh occl_mesh;
  bool occl_box = true;
  double occl_w = 0, occl_d = 0, occl_r = 0, occl_hmax = 0;
  std::vector<const Placed*> placed{&objs[0]};
  if (occluded) {
    occl_box = rng.bernoulli(0.65);
    double half_depth;
    if (occl_box) {
      occl_w = rng.uniform(0.8, 1.6) * 2 * r_t;
      occl_d = warehouse ? rng.uniform(300, 800) : rng.uniform(30, 80);
      half_depth = 0.5 * occl_d;
    } else {
      occl_r = std::max(warehouse ? 150.0 : 20.0, rng.uniform(0.5, 1.0) * r_t);
      half_depth = occl_r;
    }
    const double lateral = rng.uniform(-0.5, 0.5) * r_t;
    const double along = r_t + half_depth + gap + rng.uniform(0.0, 0.5) * r_t;
    const Vec2 c = g * along + perp * lateral;
    const double yaw = std::atan2(perp.y(), perp.x());  // box x axis (width) along perp
    Polygon local;
    if (occl_box) {
      local = {{-occl_w / 2, -occl_d / 2}, {occl_w / 2, -occl_d / 2}, {occl_w / 2, occl_d / 2}, {-occl_w / 2, occl_d / 2}};
    } else {
      for (int k = 0; k < 24; ++k)
        local.emplace_back(occl_r * std::cos(2 * M_PI * k / 24), occl_r * std::sin(2 * M_PI * k / 24));
    }
    occl.footprint = transform_footprint(local, yaw, c);
    occl.T_world_model.R = axis_angle(Vec3::UnitZ(), yaw);
    occl.T_world_model.t = Vec3(c.x(), c.y(), 0);
    // Height hiding the whole target (line from the eye over the target's
    // top, at the occluder's far side), with a margin; below the camera.
    const double D = Vec2(eye.x(), eye.y()).norm();
    const double x = std::max(0.0, along - half_depth);
    double h = tgt.height + (eye.z() - tgt.height) * std::min(1.0, x / std::max(D, 1e-6));
    occl_hmax = std::min(1.3 * h + 20.0, eye.z() - 100.0);
    if (occl_hmax <= 5.0) {
      why = "no room for an occluder";
      return false;
    }
    occl.radius = std::sqrt(std::pow(occl_box ? 0.5 * std::hypot(occl_w, occl_d) : occl_r, 2) + occl_hmax * occl_hmax);
    // Camera clearance for the tallest occluder.
    if ((Vec3(c.x(), c.y(), 0.5 * occl_hmax) - eye).norm() < occl.radius + rset.near_mm + 50) {
      why = "occluder too close to the camera";
      return false;
    }
    for (const auto& q : occl.footprint)
      if ((warehouse && (q - wall_point).dot(wall_n) < gap) ||
          (!warehouse && (std::abs(q.x()) > 0.5 * s.table.size_mm || std::abs(q.y()) > 0.5 * s.table.size_mm))) {
        why = "occluder does not fit";
        return false;
      }
    placed.push_back(&occl);
  }

  // 4. Other objects, scattered around the target (a disc as wide as the
  // view at the target's distance) with their centre inside the image.
  const double spread = std::max(3.0 * r_t, dist * std::tan(half_fov_min()));
  const int n_other = pool.empty() ? 0 : rng.uniform_int(s.distractors.min_count, s.distractors.max_count);
  for (int k = 0; k < n_other; ++k) {
    const int mi = pool[rng.uniform_int(0, static_cast<int>(pool.size()) - 1)];
    const int ri = sample_rest_pose(rest[mi], s.distractors.upright_probability, rng);
    bool ok = false;
    for (int tries = 0; tries < 60 && !ok; ++tries) {
      const double r = spread * std::sqrt(rng.uniform());
      const double phi = rng.uniform(0, 2 * M_PI);
      const double yaw = rng.uniform(0, 2 * M_PI);
      Placed p = on_ground(mi, ri, yaw, Vec2(r * std::cos(phi), r * std::sin(phi)));
      const Vec3 c = T_cam_world * (p.T_world_model.t + Vec3(0, 0, 0));
      if (c.z() <= rset.near_mm) continue;
      const auto uv = K.project(c);
      if (uv.x() < -0.05 * K.width || uv.x() > 1.05 * K.width || uv.y() < -0.05 * K.height ||
          uv.y() > 1.05 * K.height)
        continue;
      if (!fits(p, placed)) continue;
      objs.push_back(std::move(p));
      ok = true;
    }
    if (!ok) {
      why = "could not place " + std::to_string(n_other) + " other objects";
      return false;
    }
    placed.clear();
    for (const auto& o : objs) placed.push_back(&o);
    if (occluded) placed.push_back(&occl);
  }

  std::vector<const Placed*> obj_ptrs;
  for (const auto& o : objs) obj_ptrs.push_back(&o);

  // Target visibility.
  AloneStats target_alone;
  if (!alone(objs[0], T_cam_world, target_alone) || target_alone.px_all == 0) {
    why = "target outside the image";
    return false;
  }
  auto target_visib = [&](const std::vector<const Placed*>& extras) {
    const RenderOutput out = render(*renderer, obj_ptrs, extras, T_cam_world, false, bg);
    int n = 0;
    for (int32_t l : out.labels) n += (l == 0);
    return static_cast<double>(n) / target_alone.px_all;
  };
  double occl_h = 0;
  if (occluded) {
    auto set_height = [&](double h) {
      occl_mesh = occl_box ? make_box(occl_w, occl_d, h) : make_cylinder(occl_r, h, 32);
      occl.mesh = &occl_mesh;
      occl.T_world_model.t.z() = 0.5 * h;
      occl.height = h;
    };
    const double v0 = target_visib({});
    if (v0 < s.occlusion.visib_fract.lo) {
      why = "target too occluded before the occluder";
      return false;
    }
    // Visible fraction falls as the occluder grows: find the height where
    // it meets the goal by regula falsi (Illinois variant) on [0, hmax].
    double a = 0, fa = v0 - goal, b = occl_hmax, best_h = -1, best_err = 1e300;
    set_height(b);
    const double vmax = target_visib({&occl});
    double fb = vmax - goal;
    if (vmax > s.occlusion.visib_fract.hi) {
      why = "occluder too small";
      return false;
    }
    auto consider = [&](double h, double v) {
      if (v >= s.occlusion.visib_fract.lo && v <= s.occlusion.visib_fract.hi && std::abs(v - goal) < best_err)
        best_h = h, best_err = std::abs(v - goal);
    };
    consider(b, vmax);
    if (fa <= 0) consider(0.02 * occl_hmax, v0);  // already occluded enough: a token occluder
    int side = 0;
    for (int it = 0; it < 12 && best_err > 0.02 && fa > 0 && fb < 0; ++it) {
      double c = b - fb * (b - a) / (fb - fa);
      if (!(c > a && c < b)) c = 0.5 * (a + b);
      set_height(c);
      const double fc = target_visib({&occl}) - goal;
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
    set_height(best_h);
    occl_h = best_h;
  } else {
    const double v = target_visib({});
    if (v < s.min_target_visib) {
      why = "target not visible enough";
      return false;
    }
  }
  img.occluded = occluded;
  img.occluder_height_mm = occl_h;

  // 5. Final render with the background, ground truth, noise.
  std::vector<const Placed*> extras;
  if (occluded) extras.push_back(&occl);
  RenderOutput full = render(*renderer, obj_ptrs, extras, T_cam_world, true, bg);
  const int W = K.width, H = K.height;
  const size_t npx = static_cast<size_t>(W) * H;

  std::vector<int> remap(objs.size(), -1);
  std::vector<AloneStats> stats;
  img.info = ImageInfo();
  img.info.im_id = im_id;
  img.info.K = K;
  img.info.depth_scale = s.depth_scale;
  img.names.clear();
  // Silhouettes of each object alone. Objects inside the image whose
  // projected boxes are disjoint cannot overlap: they are rendered together
  // (same pixels as one by one, fewer renders).
  std::vector<AloneStats> alone_stats(objs.size());
  std::vector<char> present(objs.size(), 0);
  alone_stats[0] = target_alone;
  present[0] = 1;
  std::vector<std::vector<int>> groups;
  std::vector<std::vector<Eigen::AlignedBox2d>> member_boxes;
  for (size_t i = 1; i < objs.size(); ++i) {
    double umin, umax, vmin, vmax;
    if (!project_bbox(objs[i], T_cam_world, umin, umax, vmin, vmax)) continue;
    if (umax < -0.5 || vmax < -0.5 || umin > W - 0.5 || vmin > H - 0.5) continue;  // outside the image
    if (!(umin >= -0.5 && vmin >= -0.5 && umax <= W - 0.5 && vmax <= H - 0.5)) {
      present[i] = alone(objs[i], T_cam_world, alone_stats[i]);  // crosses the border: tiles
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
      items.push_back({objs[group[j]].mesh, T_cam_world * objs[group[j]].T_world_model, static_cast<int>(j)});
    const RenderOutput out = renderer->render(items);
    std::vector<std::array<int, 4>> bb(group.size(), {{W, H, -1, -1}});
    for (int v = 0; v < H; ++v)
      for (int u = 0; u < W; ++u) {
        const int32_t l = out.labels[static_cast<size_t>(v) * W + u];
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
  for (size_t i = 0; i < objs.size(); ++i) {
    if (!present[i]) continue;
    AloneStats& st = alone_stats[i];
    remap[i] = static_cast<int>(stats.size());
    stats.push_back(std::move(st));
    GtObject gt;
    gt.obj_id = models[objs[i].model].obj_id;
    gt.T_cam_model = T_cam_world * objs[i].T_world_model;
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

  for (size_t k = 0; k < stats.size(); ++k) {
    GtInfo gi;
    gi.px_count_all = stats[k].px_all;
    gi.bbox_obj = stats[k].bbox;
    int valid = 0;
    for (int p : stats[k].pixels) valid += img.depth.z[p] > 0.f;
    gi.px_count_valid = valid;
    int visib = 0, u0 = W, v0 = H, u1 = -1, v1 = -1;
    for (int v = 0; v < H; ++v)
      for (int u = 0; u < W; ++u)
        if (img.labels[static_cast<size_t>(v) * W + u] == static_cast<int>(k)) {
          ++visib;
          u0 = std::min(u0, u), u1 = std::max(u1, u), v0 = std::min(v0, v), v1 = std::max(v1, v);
        }
    gi.px_count_visib = visib;
    gi.bbox_visib = bbox_of(u0, v0, u1, v1);
    gi.visib_fract = gi.px_count_all > 0 ? static_cast<double>(visib) / gi.px_count_all : 0.0;
    img.info.gt_info.push_back(gi);
  }
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

std::vector<uint8_t> depth_preview_rgb(const DepthImage& depth, const Intrinsics* K) {
  std::vector<float> valid;
  for (float z : depth.z)
    if (z > 0.f) valid.push_back(z);
  float lo = 0, hi = 1;
  if (!valid.empty()) {
    const size_t a = valid.size() * 2 / 100, b = std::min(valid.size() - 1, valid.size() * 98 / 100);
    std::nth_element(valid.begin(), valid.begin() + a, valid.end());
    lo = valid[a];
    std::nth_element(valid.begin(), valid.begin() + b, valid.end());
    hi = valid[b];
    if (hi <= lo) hi = lo + 1;
  }
  // Warm (near) to cool (far), shaded by the surface normal (light at the
  // camera) so object outlines stand out.
  static const float keys[5][3] = {{165, 0, 38}, {244, 109, 67}, {254, 224, 144}, {116, 173, 209}, {49, 54, 149}};
  const int W = depth.width, H = depth.height;
  std::vector<uint8_t> rgb(depth.z.size() * 3, 0);
  for (int v = 0; v < H; ++v)
    for (int u = 0; u < W; ++u) {
      const size_t i = static_cast<size_t>(v) * W + u;
      const float z = depth.z[i];
      if (!(z > 0.f)) continue;
      float shade = 1.f;
      if (K && u > 0 && v > 0 && u + 1 < W && v + 1 < H) {
        const float zl = depth.at(u - 1, v), zr = depth.at(u + 1, v), zu = depth.at(u, v - 1), zd = depth.at(u, v + 1);
        const float jump = 30.f;
        if (zl > 0 && zr > 0 && zu > 0 && zd > 0 && std::abs(zr - zl) < 2 * jump && std::abs(zd - zu) < 2 * jump) {
          const Vec3 dx = K->backproject(u + 1, v, zr) - K->backproject(u - 1, v, zl);
          const Vec3 dy = K->backproject(u, v + 1, zd) - K->backproject(u, v - 1, zu);
          Vec3 n = dy.cross(dx);
          const Vec3 ray = K->backproject(u, v, z).normalized();
          if (n.norm() > 0) {
            n.normalize();
            shade = static_cast<float>(0.3 + 0.7 * std::abs(n.dot(ray)));
          }
        } else {
          shade = 0.3f;  // depth edge
        }
      }
      const float t = std::clamp((z - lo) / (hi - lo), 0.f, 1.f) * 4.f;
      const int k = std::min(3, static_cast<int>(t));
      const float f = t - k;
      for (int c = 0; c < 3; ++c)
        rgb[3 * i + c] = static_cast<uint8_t>(std::lround(shade * (keys[k][c] * (1 - f) + keys[k + 1][c] * f)));
    }
  return rgb;
}

GenerateSummary generate_dataset(const SceneSettings& settings, const std::string& out_dir,
                                 void (*progress)(int done, int total), int threads) {
  Timer timer;
  const fs::path out(out_dir);
  if (out.empty() || out.filename() == "." || out.filename() == "..")
    throw InputError(out_dir, "--out", "not a usable output directory name");
  std::error_code ec;
  if (fs::exists(out)) {
    if (!fs::is_directory(out)) throw InputError(out_dir, "--out", "exists and is not a directory");
    if (!fs::is_empty(out) && !fs::exists(out / "posebench_scene.json"))
      throw InputError(out_dir, "--out", "exists and is not a posebench scene set; remove it or choose another");
  }
  // Loads models (InputError for bad ones) before anything is written.
  SceneGenerator gen(settings);
  const SceneSettings& s = gen.settings();

  const fs::path tmp = out.string() + ".partial";
  fs::remove_all(tmp, ec);
  GenerateSummary sum;
  try {
    fs::create_directories(tmp / "models");
    const fs::path scene_dir = tmp / "test" / bop_id(s.scene_id);
    fs::create_directories(scene_dir / "depth");
    if (s.masks) fs::create_directories(scene_dir / "mask_visib");

    std::map<int, ModelInfo> infos;
    for (const auto& m : gen.models()) {
      write_ply((tmp / "models" / ("obj_" + bop_id(m.obj_id) + ".ply")).string(), m.mesh);
      infos[m.obj_id] = m.info;
    }
    write_models_info((tmp / "models" / "models_info.json").string(), infos);
    write_camera_json((tmp / "camera.json").string(), s.sensor.K, s.depth_scale);

    // Images are independent (own seeds): any number of workers, each with
    // its own generator (renderer), gives the same files.
    struct Done {
      ImageInfo info;
      nlohmann::ordered_json trace;
      double target_visib = 0;
    };
    std::vector<Done> done(s.images);
    auto make_image = [&](SceneGenerator& g, int im) {
      GeneratedImage img = g.generate(im);
      const std::string iid = bop_id(im);
      write_depth_png((scene_dir / "depth" / (iid + ".png")).string(), img.depth, s.depth_scale);
      const int W = img.depth.width, H = img.depth.height;
      if (s.masks)
        for (size_t k = 0; k < img.info.gt.size(); ++k) {
          std::vector<uint8_t> m(static_cast<size_t>(W) * H, 0);
          for (size_t p = 0; p < m.size(); ++p) m[p] = img.labels[p] == static_cast<int>(k) ? 255 : 0;
          write_gray8_png((scene_dir / "mask_visib" / (iid + "_" + bop_id(static_cast<int>(k)) + ".png")).string(), W,
                          H, m);
        }
      if (im == 0) write_rgb8_png((tmp / "depth_preview.png").string(), W, H, depth_preview_rgb(img.depth, &s.sensor.K));
      Done& d = done[im];
      d.target_visib = img.info.gt_info.empty() ? 0.0 : img.info.gt_info[0].visib_fract;
      nlohmann::ordered_json& t = d.trace;
      t["im_id"] = im;
      t["attempts"] = img.attempts;
      t["camera_distance_mm"] = img.camera_distance_mm;
      t["camera_elevation_deg"] = img.camera_elevation_deg;
      t["camera_azimuth_deg"] = img.camera_azimuth_deg;
      std::vector<double> Tw;
      const Mat4 M = img.T_world_cam.matrix();
      for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) Tw.push_back(M(r, c));
      t["T_world_cam"] = Tw;
      t["occluded"] = img.occluded;
      t["occluder_height_mm"] = img.occluder_height_mm;
      t["objects"] = img.names;
      t["target_visib_fract"] = d.target_visib;
      d.info = std::move(img.info);
    };
    const int workers = std::max(1, std::min(threads, s.images));
    std::atomic<int> next{0};
    std::mutex mu;
    std::exception_ptr error;
    int finished = 0;
    auto work = [&](SceneGenerator* g) {
      try {
        std::unique_ptr<SceneGenerator> own;
        if (!g) {
          own = gen.clone();
          g = own.get();
        }
        for (;;) {
          {
            std::lock_guard<std::mutex> lock(mu);
            if (error) return;
          }
          const int im = next++;
          if (im >= s.images) return;
          make_image(*g, im);
          std::lock_guard<std::mutex> lock(mu);
          ++finished;
          if (progress) progress(finished, s.images);
        }
      } catch (...) {
        std::lock_guard<std::mutex> lock(mu);
        if (!error) error = std::current_exception();
      }
    };
    std::vector<std::thread> pool;
    for (int w = 1; w < workers; ++w) pool.emplace_back(work, nullptr);
    work(&gen);
    for (auto& t : pool) t.join();
    if (error) std::rethrow_exception(error);

    SceneInfo scene;
    scene.scene_id = s.scene_id;
    nlohmann::ordered_json trace = nlohmann::ordered_json::array();
    double visib_sum = 0, visib_min = 1;
    for (int im = 0; im < s.images; ++im) {
      visib_sum += done[im].target_visib;
      visib_min = std::min(visib_min, done[im].target_visib);
      sum.objects += static_cast<int>(done[im].info.gt.size());
      trace.push_back(std::move(done[im].trace));
      scene.images[im] = std::move(done[im].info);
    }
    write_scene_json(scene_dir.string(), scene);

    sum.images = s.images;
    sum.mean_target_visib = visib_sum / s.images;
    sum.min_target_visib = visib_min;
    nlohmann::ordered_json j;
    j["format"] = "posebench scene set";
    j["settings"] = nlohmann::ordered_json::parse(scene_settings_json(s));
    nlohmann::ordered_json jm = nlohmann::ordered_json::array();
    for (const auto& m : gen.models())
      jm.push_back({{"obj_id", m.obj_id}, {"name", m.name}, {"scale", m.scale}, {"diameter", m.info.diameter}});
    j["models"] = jm;
    j["summary"] = {{"images", sum.images}, {"objects", sum.objects},
                    {"mean_target_visib_fract", sum.mean_target_visib},
                    {"min_target_visib_fract", sum.min_target_visib}};
    j["images"] = trace;
    // Written last: its presence marks a complete scene set.
    atomic_write_text((tmp / "posebench_scene.json").string(), j.dump(2) + "\n");

    if (fs::exists(out)) {
      const fs::path old = out.string() + ".old";
      fs::remove_all(old, ec);
      fs::rename(out, old);
      fs::rename(tmp, out);
      fs::remove_all(old, ec);
    } else {
      if (out.has_parent_path()) fs::create_directories(out.parent_path());
      fs::rename(tmp, out);
    }
  } catch (const fs::filesystem_error& e) {
    fs::remove_all(tmp, ec);
    throw InputError(out_dir, "--out", std::string("cannot write the scene set: ") + e.what());
  } catch (...) {
    fs::remove_all(tmp, ec);
    throw;
  }
  sum.out_dir = out.string();
  sum.preview_png = (out / "depth_preview.png").string();
  sum.seconds = timer.seconds();
  return sum;
}

}  // namespace pb
