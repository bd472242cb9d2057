// Sensor profiles and depth noise models: see sensor.h for the models.
#include "render/sensor.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include "core/error.h"

namespace pb {

namespace {

constexpr double kDeg = M_PI / 180.0;

bool valid_depth(float z) { return z > 0.f && std::isfinite(z); }

// Pixels whose viewing ray meets the surface at more than max_deg from the
// normal (zero normals are never grazing).
std::vector<uint8_t> grazing_mask(const DepthImage& depth, const std::vector<Vec3f>& normals,
                                  const Intrinsics& K, double max_deg) {
  const int W = depth.width, H = depth.height;
  std::vector<uint8_t> mask(static_cast<size_t>(W) * H, 0);
  const double cos_max = std::cos(max_deg * kDeg);
  for (int v = 0; v < H; ++v)
    for (int u = 0; u < W; ++u) {
      const size_t px = static_cast<size_t>(v) * W + u;
      if (!valid_depth(depth.z[px])) continue;
      const Vec3 n = normals[px].cast<double>();
      if (n.squaredNorm() < 1e-12) continue;
      const Vec3 ray = Vec3((u - K.cx) / K.fx, (v - K.cy) / K.fy, 1.0).normalized();
      const double c = std::abs(n.normalized().dot(ray));
      mask[px] = c < cos_max;
    }
  return mask;
}

const std::vector<Vec3f>& normals_for(const DepthImage& depth, const RenderOutput& render, const Intrinsics& K,
                                      std::vector<Vec3f>& storage) {
  if (render.normals.size() == depth.z.size()) return render.normals;
  storage = estimate_normals(depth, K);
  return storage;
}

void apply_gaussian(DepthImage& depth, const GaussianNoise& g, Rng& rng) {
  if (g.sigma_mm <= 0) return;
  for (float& z : depth.z)
    if (valid_depth(z)) z = static_cast<float>(z + rng.normal(0.0, g.sigma_mm));
}

void apply_structured_light(DepthImage& depth, const std::vector<Vec3f>& normals, const Intrinsics& K,
                            const StructuredLightNoise& s, Rng& rng) {
  const int W = depth.width, H = depth.height;
  const size_t N = depth.z.size();
  const double fb = K.fx * s.baseline_mm;
  std::vector<double> d_true(N, 0.0), d_noisy(N, 0.0);
  std::vector<uint8_t> ok(N, 0);
  std::vector<uint8_t> shadow;
  if (s.shadows) shadow = projector_shadow_mask(depth, K, s.baseline_mm);
  const std::vector<uint8_t> grazing = grazing_mask(depth, normals, K, s.max_incidence_deg);
  for (size_t px = 0; px < N; ++px) {
    if (!valid_depth(depth.z[px])) continue;
    d_true[px] = fb / depth.z[px];
    ok[px] = !grazing[px] && !(s.shadows && shadow[px]);
  }
  for (size_t px = 0; px < N; ++px)
    if (ok[px]) d_noisy[px] = d_true[px] + rng.normal(0.0, s.disparity_sigma_px);
  const int r = std::max(0, s.smoothing_radius_px);
  for (int v = 0; v < H; ++v)
    for (int u = 0; u < W; ++u) {
      const size_t px = static_cast<size_t>(v) * W + u;
      if (!ok[px]) {
        depth.z[px] = 0.f;
        continue;
      }
      double sum = 0.0;
      int count = 0;
      for (int dv = -r; dv <= r; ++dv) {
        const int vv = v + dv;
        if (vv < 0 || vv >= H) continue;
        for (int du = -r; du <= r; ++du) {
          const int uu = u + du;
          if (uu < 0 || uu >= W) continue;
          const size_t q = static_cast<size_t>(vv) * W + uu;
          if (!ok[q] || std::abs(d_true[q] - d_true[px]) > s.smoothing_edge_px) continue;
          sum += d_noisy[q];
          ++count;
        }
      }
      const double d = sum / count;  // count >= 1: the pixel itself
      const double dq = std::round(d / s.disparity_step_px) * s.disparity_step_px;
      depth.z[px] = dq > 0 ? static_cast<float>(fb / dq) : 0.f;
    }
}

// The driver's edge filter (TimeOfFlightNoise::driver_edge_filter): judges
// every pixel against the nearest and farthest valid depth of its 3x3
// window in the unfiltered image, so the result does not depend on the
// scan order. Border pixels are kept (no full window).
void drop_flying_pixels(DepthImage& depth, const TimeOfFlightNoise& t) {
  const int W = depth.width, H = depth.height;
  const DepthImage raw = depth;
  for (int v = 1; v + 1 < H; ++v)
    for (int u = 1; u + 1 < W; ++u) {
      const float z = raw.at(u, v);
      if (!valid_depth(z)) continue;
      float lo = z, hi = z;
      for (int dv = -1; dv <= 1; ++dv)
        for (int du = -1; du <= 1; ++du) {
          const float zq = raw.at(u + du, v + dv);
          if (!valid_depth(zq)) continue;
          lo = std::min(lo, zq);
          hi = std::max(hi, zq);
        }
      const double behind_nearest = z - lo, before_farthest = hi - z;
      if (behind_nearest > t.edge_filter_close_mm && before_farthest > t.edge_filter_far_mm &&
          std::max(behind_nearest, before_farthest) > t.edge_filter_span_mm)
        depth.z[static_cast<size_t>(v) * W + u] = 0.f;
    }
}

void apply_tof(DepthImage& depth, const std::vector<Vec3f>& normals, const Intrinsics& K,
               const TimeOfFlightNoise& t, Rng& rng) {
  const int W = depth.width, H = depth.height;
  const DepthImage truth = depth;
  const std::vector<uint8_t> grazing = grazing_mask(truth, normals, K, t.max_incidence_deg);
  for (int v = 0; v < H; ++v)
    for (int u = 0; u < W; ++u) {
      const size_t px = static_cast<size_t>(v) * W + u;
      const float z0 = truth.z[px];
      if (!valid_depth(z0) || grazing[px]) {
        depth.z[px] = 0.f;
        continue;
      }
      // The largest depth jump to a valid 8-neighbour.
      float other = z0;
      for (int dv = -1; dv <= 1; ++dv)
        for (int du = -1; du <= 1; ++du) {
          const int uu = u + du, vv = v + dv;
          if ((du == 0 && dv == 0) || uu < 0 || vv < 0 || uu >= W || vv >= H) continue;
          const float zq = truth.at(uu, vv);
          if (valid_depth(zq) && std::abs(zq - z0) > std::abs(other - z0)) other = zq;
        }
      double z = z0;
      if (std::abs(other - z0) > t.edge_jump_mm && rng.bernoulli(t.flying_fraction)) {
        const double lo = std::min(z0, other), hi = std::max(z0, other);
        z = lo + rng.uniform() * (hi - lo);
      }
      const double zm = z / 1000.0;
      z += rng.normal(0.0, t.sigma_base_mm + t.sigma_per_m2_mm * zm * zm);
      depth.z[px] = z > 0 ? static_cast<float>(z) : 0.f;
    }
  if (t.driver_edge_filter) drop_flying_pixels(depth, t);
}

void check_intrinsics(const YamlNode& node, const Intrinsics& K) {
  if (K.width < 1 || K.width > 16384) node["width"].fail("must be 1..16384");
  if (K.height < 1 || K.height > 16384) node["height"].fail("must be 1..16384");
  if (!(K.fx > 0) || !std::isfinite(K.fx)) node[node.has("fx") ? "fx" : "hfov_deg"].fail("must be positive");
  if (!(K.fy > 0) || !std::isfinite(K.fy)) node[node.has("fy") ? "fy" : "vfov_deg"].fail("must be positive");
  if (!std::isfinite(K.cx)) node["cx"].fail("must be finite");
  if (!std::isfinite(K.cy)) node["cy"].fail("must be finite");
}

double fov_deg(const YamlNode& node, const std::string& key) {
  const double v = node.get<double>(key);
  if (!(v > 0 && v < 180)) node[key].fail("must be in (0, 180) degrees");
  return v;
}

bool is_builtin(const std::string& name) {
  const auto names = sensor_names();
  return std::find(names.begin(), names.end(), name) != names.end();
}

std::string unknown_sensor(const std::string& name) {
  std::string list;
  for (const auto& n : sensor_names()) list += (list.empty() ? "" : ", ") + n;
  return "unknown sensor '" + name + "' (built in: " + list +
         "; or give a map with width, height, fx, fy, cx, cy)";
}

}  // namespace

std::vector<std::string> sensor_names() { return {"synthetic", "astra", "kinect_one"}; }

SensorProfile sensor_profile(const std::string& name, const std::string& file, const std::string& field) {
  SensorProfile s;
  s.name = name;
  if (name == "synthetic") {
    // Ideal rasterized sensor of the thesis's synthetic images.
    s.K = Intrinsics::from_fov(512, 512, 30, 30);
    s.depth_scale = 0.2;  // uint16 holds up to 13.1 m (warehouse walls)
    s.min_range_mm = 100;
    s.max_range_mm = 13000;
    s.noise.model = "gaussian";
  } else if (name == "astra") {
    // Structured light, 0.4 to 8 m.
    s.K = Intrinsics::from_fov(640, 480, 59, 46);
    s.depth_scale = 0.125;  // uint16 holds up to 8.19 m
    s.min_range_mm = 400;
    s.max_range_mm = 8000;
    s.noise.model = "structured_light";
  } else if (name == "kinect_one") {
    // Time of flight, 0.5 to 4.5 m.
    s.K = Intrinsics::from_fov(512, 424, 57, 43);
    s.depth_scale = 0.1;
    s.min_range_mm = 500;
    s.max_range_mm = 4500;
    s.noise.model = "tof";
  } else {
    throw InputError(file, field, unknown_sensor(name));
  }
  return s;
}

SensorProfile parse_sensor(const YamlNode& node) {
  if (!node.defined()) node.fail("missing sensor (a name or a map of intrinsics)");
  if (node.is_scalar()) {
    const std::string name = node.as<std::string>();
    if (!is_builtin(name)) node.fail(unknown_sensor(name));  // names file, field and line
    return sensor_profile(name, node.file(), node.path());
  }
  node.check_keys({"name", "width", "height", "fx", "fy", "cx", "cy", "hfov_deg", "vfov_deg", "depth_scale",
                   "min_range_mm", "max_range_mm"});
  const bool has_intrinsics = node.has("width") || node.has("height") || node.has("fx") || node.has("fy") ||
                              node.has("cx") || node.has("cy") || node.has("hfov_deg") || node.has("vfov_deg");
  SensorProfile s;
  const std::string name = node.get_or<std::string>("name", "custom");
  if (!has_intrinsics) {
    if (!is_builtin(name)) node["name"].fail(unknown_sensor(name));
    s = sensor_profile(name, node.file(), node["name"].path());
  } else {
    s.name = name;
    s.noise.model = "gaussian";
    s.min_range_mm = 100;
    s.max_range_mm = 6500;
    s.depth_scale = 0.1;
    Intrinsics& K = s.K;
    K.width = node.get<int>("width");
    K.height = node.get<int>("height");
    if (K.width < 1 || K.width > 16384) node["width"].fail("must be 1..16384");
    if (K.height < 1 || K.height > 16384) node["height"].fail("must be 1..16384");
    const bool focal = node.has("fx") || node.has("fy");
    const bool fov = node.has("hfov_deg") || node.has("vfov_deg");
    if (focal && fov) node.fail("give either fx, fy or hfov_deg, vfov_deg, not both");
    if (fov) {
      K = Intrinsics::from_fov(K.width, K.height, fov_deg(node, "hfov_deg"), fov_deg(node, "vfov_deg"));
    } else {
      K.fx = node.get<double>("fx");
      K.fy = node.get<double>("fy");
    }
    K.cx = node.get_or<double>("cx", 0.5 * (K.width - 1));
    K.cy = node.get_or<double>("cy", 0.5 * (K.height - 1));
    check_intrinsics(node, K);
  }
  s.depth_scale = node.get_positive("depth_scale", s.depth_scale);
  s.min_range_mm = node.get_nonnegative("min_range_mm", s.min_range_mm);
  s.max_range_mm = node.get_positive("max_range_mm", s.max_range_mm);
  if (!(s.max_range_mm > s.min_range_mm))
    node["max_range_mm"].fail("must be larger than min_range_mm (" + std::to_string(s.min_range_mm) + ")");
  if (s.max_range_mm > 65535.0 * s.depth_scale)
    node[node.has("max_range_mm") ? "max_range_mm" : "depth_scale"].fail(
        "max_range_mm " + std::to_string(s.max_range_mm) + " does not fit a uint16 depth PNG with depth_scale " +
        std::to_string(s.depth_scale) + " (limit 65535 * depth_scale)");
  return s;
}

NoiseSettings parse_noise(const YamlNode& node, const NoiseSettings& base) {
  NoiseSettings n = base;
  if (!node.defined()) return n;
  const std::set<std::string> models = {"none", "gaussian", "structured_light", "tof"};
  auto check_model = [&](const YamlNode& at, const std::string& m) {
    if (!models.count(m))
      at.fail("unknown noise model '" + m + "' (none, gaussian, structured_light, tof)");
  };
  if (node.is_scalar()) {
    n.model = node.as<std::string>();
    check_model(node, n.model);
    return n;
  }
  const std::set<std::string> gaussian_keys = {"sigma_mm"};
  const std::set<std::string> sl_keys = {"baseline_mm",         "disparity_step_px", "disparity_sigma_px",
                                         "smoothing_radius_px", "smoothing_edge_px", "max_incidence_deg",
                                         "shadows"};
  const std::set<std::string> tof_keys = {"sigma_base_mm",        "sigma_per_m2_mm",    "edge_jump_mm",
                                          "flying_fraction",      "max_incidence_deg",  "driver_edge_filter",
                                          "edge_filter_close_mm", "edge_filter_far_mm", "edge_filter_span_mm"};
  std::set<std::string> all = {"model"};
  all.insert(gaussian_keys.begin(), gaussian_keys.end());
  all.insert(sl_keys.begin(), sl_keys.end());
  all.insert(tof_keys.begin(), tof_keys.end());
  node.check_keys(all);
  n.model = node.get_or<std::string>("model", base.model);
  check_model(node["model"], n.model);
  const std::set<std::string>* own = nullptr;
  if (n.model == "gaussian") own = &gaussian_keys;
  if (n.model == "structured_light") own = &sl_keys;
  if (n.model == "tof") own = &tof_keys;
  for (const std::string& k : node.keys())
    if (k != "model" && (!own || !own->count(k)))
      node[k].fail("does not apply to noise model '" + n.model + "'");

  auto incidence = [&](double fallback) {
    const double v = node.get_or<double>("max_incidence_deg", fallback);
    if (!(v > 0 && v <= 90)) node["max_incidence_deg"].fail("must be in (0, 90] degrees");
    return v;
  };
  if (n.model == "gaussian") {
    n.gaussian.sigma_mm = node.get_nonnegative("sigma_mm", n.gaussian.sigma_mm);
  } else if (n.model == "structured_light") {
    StructuredLightNoise& s = n.structured_light;
    s.baseline_mm = node.get_positive("baseline_mm", s.baseline_mm);
    s.disparity_step_px = node.get_positive("disparity_step_px", s.disparity_step_px);
    s.disparity_sigma_px = node.get_nonnegative("disparity_sigma_px", s.disparity_sigma_px);
    s.smoothing_radius_px = node.get_or<int>("smoothing_radius_px", s.smoothing_radius_px);
    if (s.smoothing_radius_px < 0 || s.smoothing_radius_px > 10)
      node["smoothing_radius_px"].fail("must be 0..10");
    s.smoothing_edge_px = node.get_nonnegative("smoothing_edge_px", s.smoothing_edge_px);
    s.max_incidence_deg = incidence(s.max_incidence_deg);
    node.read("shadows", s.shadows);
  } else if (n.model == "tof") {
    TimeOfFlightNoise& t = n.tof;
    t.sigma_base_mm = node.get_nonnegative("sigma_base_mm", t.sigma_base_mm);
    t.sigma_per_m2_mm = node.get_nonnegative("sigma_per_m2_mm", t.sigma_per_m2_mm);
    t.edge_jump_mm = node.get_positive("edge_jump_mm", t.edge_jump_mm);
    t.flying_fraction = node.get_nonnegative("flying_fraction", t.flying_fraction);
    if (t.flying_fraction > 1) node["flying_fraction"].fail("must be in [0, 1]");
    t.max_incidence_deg = incidence(t.max_incidence_deg);
    node.read("driver_edge_filter", t.driver_edge_filter);
    t.edge_filter_close_mm = node.get_nonnegative("edge_filter_close_mm", t.edge_filter_close_mm);
    t.edge_filter_far_mm = node.get_nonnegative("edge_filter_far_mm", t.edge_filter_far_mm);
    t.edge_filter_span_mm = node.get_nonnegative("edge_filter_span_mm", t.edge_filter_span_mm);
  }
  return n;
}

std::vector<uint8_t> projector_shadow_mask(const DepthImage& depth, const Intrinsics& K, double baseline_mm) {
  // The projector shares the camera's orientation and intrinsics and sits at
  // +b along x, so a camera point at pixel (u, v), depth z, appears in the
  // projector at column u_p = u - fx b / z of the same row. Along one
  // projector ray, nearer points have larger camera u. Z-buffering in the
  // projector therefore reduces to: a pixel is shadowed if some pixel to its
  // right in the row maps to a smaller projector column (it passed in front).
  const int W = depth.width, H = depth.height;
  std::vector<uint8_t> mask(static_cast<size_t>(W) * H, 0);
  const double fb = K.fx * baseline_mm;
  constexpr double kTol = 1e-3;  // px; a surface seen exactly edge-on is not self-shadowed
  for (int v = 0; v < H; ++v) {
    double min_up = std::numeric_limits<double>::infinity();
    for (int u = W - 1; u >= 0; --u) {
      const float z = depth.at(u, v);
      if (!valid_depth(z)) continue;
      const double up = u - fb / z;
      if (up > min_up + kTol) mask[static_cast<size_t>(v) * W + u] = 1;
      min_up = std::min(min_up, up);
    }
  }
  return mask;
}

std::vector<Vec3f> estimate_normals(const DepthImage& depth, const Intrinsics& K, double edge_jump_mm) {
  const int W = depth.width, H = depth.height;
  std::vector<Vec3f> normals(static_cast<size_t>(W) * H, Vec3f::Zero());
  auto point = [&](int u, int v) { return K.backproject(u, v, depth.at(u, v)); };
  // A neighbour on the same surface as (u, v), or none.
  auto same = [&](int u, int v, int uu, int vv) {
    if (uu < 0 || vv < 0 || uu >= W || vv >= H) return false;
    const float z = depth.at(uu, vv);
    return valid_depth(z) && std::abs(z - depth.at(u, v)) <= edge_jump_mm;
  };
  for (int v = 0; v < H; ++v)
    for (int u = 0; u < W; ++u) {
      if (!valid_depth(depth.at(u, v))) continue;
      const Vec3 p = point(u, v);
      const bool r = same(u, v, u + 1, v), l = same(u, v, u - 1, v);
      const bool d = same(u, v, u, v + 1), t = same(u, v, u, v - 1);
      if (!(r || l) || !(d || t)) continue;
      const Vec3 dx = (r ? point(u + 1, v) : p) - (l ? point(u - 1, v) : p);
      const Vec3 dy = (d ? point(u, v + 1) : p) - (t ? point(u, v - 1) : p);
      Vec3 n = dx.cross(dy);
      const double len = n.norm();
      if (!(len > 0)) continue;
      n /= len;
      if (n.dot(p) > 0) n = -n;
      normals[static_cast<size_t>(v) * W + u] = n.cast<float>();
    }
  return normals;
}

void apply_noise(DepthImage& depth, const RenderOutput& render, const SensorProfile& sensor,
                 const NoiseSettings& noise, Rng& rng) {
  const Intrinsics& K = sensor.K;
  if (depth.width != K.width || depth.height != K.height)
    throw std::invalid_argument("apply_noise: depth image size differs from the sensor's intrinsics");
  std::vector<Vec3f> estimated;
  if (noise.model == "none") {
  } else if (noise.model == "gaussian") {
    apply_gaussian(depth, noise.gaussian, rng);
  } else if (noise.model == "structured_light") {
    apply_structured_light(depth, normals_for(depth, render, K, estimated), K, noise.structured_light, rng);
  } else if (noise.model == "tof") {
    apply_tof(depth, normals_for(depth, render, K, estimated), K, noise.tof, rng);
  } else {
    throw InputError("", "noise.model", "unknown noise model '" + noise.model + "'");
  }
  for (float& z : depth.z)
    if (!valid_depth(z) || z < sensor.min_range_mm || z > sensor.max_range_mm) z = 0.f;
}

}  // namespace pb
