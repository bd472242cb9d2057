// Rendering steps of a scene generator attempt (generator_internal.h):
// silhouettes of single objects, the target's visibility and the occluder
// height search, and the final annotated image.
#include <algorithm>
#include <array>
#include <climits>
#include <cmath>

#include "models/procedural.h"
#include "render/sensor.h"
#include "scenes/generator_internal.h"

namespace pb {

using namespace scene_detail;

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
