// Internals of the scene generator (scenes/generator.h), shared by
// generator.cpp (models, SceneGenerator), generator_layout.cpp (camera,
// background, occluder and object placement) and generator_render.cpp
// (silhouettes, occluder height, annotation). Not part of the interface.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/random.h"
#include "core/types.h"
#include "render/renderer.h"
#include "scenes/generator.h"
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

  // generator.cpp: one attempt at image im_id (false with `why`).
  bool generate_attempt(int im_id, int attempt, GeneratedImage& img, std::string& why);
  // With setups: set-up k's objects (target first, background), drawn from
  // their own stream until a reference camera accepts them as an image
  // would; false with `why` after max_attempts.
  bool setup_layout(int k, Layout& L, std::string& why);
  // With setups: image im_id's camera around its set-up (false with `why`).
  bool generate_setup_attempt(int im_id, int attempt, GeneratedImage& img, std::string& why);

  // generator_layout.cpp: the steps of an attempt, in their order of random
  // draws (false with `why` when the layout is rejected).
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

  // generator_render.cpp.
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

}  // namespace pb
