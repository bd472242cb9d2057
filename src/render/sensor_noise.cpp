// The depth noise models (see sensor.h): Gaussian, structured light, time
// of flight, applied to a rendered depth image.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "core/error.h"
#include "render/sensor.h"
#include "render/window_sums.h"

namespace pb {

namespace {

constexpr double kDeg = M_PI / 180.0;

bool valid_depth(float z) { return z > 0.f && std::isfinite(z); }

// The unit viewing ray of every pixel of K, row-major: computed once per
// thread and camera (the generator renders every image of a set with one K;
// 24 bytes per pixel, 7 MB at 640 x 480, kept by each thread).
const std::vector<Vec3>& unit_rays(const Intrinsics& K) {
  thread_local Intrinsics cached;
  thread_local std::vector<Vec3> rays;
  const bool same = cached.fx == K.fx && cached.fy == K.fy && cached.cx == K.cx && cached.cy == K.cy &&
                    cached.width == K.width && cached.height == K.height;
  if (same && rays.size() == static_cast<size_t>(K.width) * K.height) return rays;
  rays.resize(static_cast<size_t>(K.width) * K.height);
  for (int v = 0; v < K.height; ++v)
    for (int u = 0; u < K.width; ++u)
      rays[static_cast<size_t>(v) * K.width + u] = Vec3((u - K.cx) / K.fx, (v - K.cy) / K.fy, 1.0).normalized();
  cached = K;
  return rays;
}

// Pixels whose viewing ray meets the surface at more than max_deg from the
// normal (zero normals are never grazing).
std::vector<uint8_t> grazing_mask(const DepthImage& depth, const std::vector<Vec3f>& normals,
                                  const Intrinsics& K, double max_deg) {
  const size_t N = static_cast<size_t>(depth.width) * depth.height;
  std::vector<uint8_t> mask(N, 0);
  const double cos_max = std::cos(max_deg * kDeg);
  const std::vector<Vec3>& rays = unit_rays(K);
  if (!(cos_max > 0)) return mask;  // |cos| < cos_max never holds
  const double cos2 = cos_max * cos_max;
  for (size_t px = 0; px < N; ++px) {
    if (!valid_depth(depth.z[px])) continue;
    const Vec3 n = normals[px].cast<double>();
    const double n2 = n.squaredNorm();
    if (n2 < 1e-12) continue;
    // The cosine's square times |n|^2, without division or root: where it
    // is clearly apart from cos_max's (errors are ~1e-16 relative), its side
    // is the decision; near the threshold the exact expression decides.
    const double d = n.dot(rays[px]);
    const double gap = d * d - cos2 * n2;
    if (std::abs(gap) > 1e-9 * n2) {
      mask[px] = gap < 0;
    } else {
      const double c = std::abs(n.normalized().dot(rays[px]));
      mask[px] = c < cos_max;
    }
  }
  return mask;
}

const std::vector<Vec3f>& normals_for(const DepthImage& depth, const RenderOutput& render, const Intrinsics& K,
                                      std::vector<Vec3f>& storage) {
  if (render.normals.size() == depth.z.size()) return render.normals;
  storage = estimate_normals(depth, K);
  return storage;
}

void apply_structured_light_core(DepthImage& depth, const std::vector<Vec3f>& normals, const Intrinsics& K,
                                 const StructuredLightNoise& s, double shadow_baseline_mm, Rng& rng);

void apply_gaussian(DepthImage& depth, const GaussianNoise& g, Rng& rng) {
  if (g.sigma_mm <= 0) return;
  for (float& z : depth.z)
    if (valid_depth(z)) z = static_cast<float>(z + rng.normal(0.0, g.sigma_mm));
}

// Pixels next to a depth edge of the true image: a step between
// 4-neighbours larger than 10 mm + 1% of the nearer depth, or depth next to
// none (a sloped surface steps far less per pixel at these distances).
bool depth_step(float a, float b) {
  if (valid_depth(a) != valid_depth(b)) return true;
  if (!valid_depth(a)) return false;
  return std::abs(a - b) > 10.0 + 0.01 * std::min(a, b);
}

std::vector<uint8_t> depth_edges(const DepthImage& truth) {
  const int W = truth.width, H = truth.height;
  std::vector<uint8_t> e(truth.z.size(), 0);
  for (int v = 0; v < H; ++v)
    for (int u = 0; u < W; ++u) {
      const size_t p = static_cast<size_t>(v) * W + u;
      if (u + 1 < W && depth_step(truth.z[p], truth.z[p + 1])) e[p] = e[p + 1] = 1;
      if (v + 1 < H && depth_step(truth.z[p], truth.z[p + W])) e[p] = e[p + W] = 1;
    }
  return e;
}

// The nearer surface grows over the farther (StructuredLightNoise::
// edge_bleed_px): a pixel takes the measured depth of the closest pixel
// (Chebyshev distance k) whose true depth is nearer across a depth edge
// (depth_step), when k <= floor(b), or k = ceil(b) with probability
// b - floor(b).
void bleed_edges(DepthImage& depth, const DepthImage& truth, double b, Rng& rng) {
  const int W = depth.width, H = depth.height, R = static_cast<int>(std::ceil(b));
  const double frac = b - std::floor(b);
  const DepthImage measured = depth;
  for (int v = 0; v < H; ++v)
    for (int u = 0; u < W; ++u) {
      const size_t p = static_cast<size_t>(v) * W + u;
      const float zp = truth.z[p];
      int best_k = R + 1;
      size_t best = 0;
      for (int dv = -R; dv <= R; ++dv)
        for (int du = -R; du <= R; ++du) {
          const int uu = u + du, vv = v + dv, k = std::max(std::abs(du), std::abs(dv));
          if (uu < 0 || vv < 0 || uu >= W || vv >= H || k >= best_k || k == 0) continue;
          const size_t q = static_cast<size_t>(vv) * W + uu;
          const float zq = truth.z[q];
          if (valid_depth(measured.z[q]) && valid_depth(zq) && (!valid_depth(zp) || zq < zp) && depth_step(zq, zp))
            best_k = k, best = q;
        }
      if (best_k > R) continue;
      if (best_k == R && frac > 0 && !rng.bernoulli(frac)) continue;
      depth.z[p] = measured.z[best];
    }
}

// No depth near edges (edge_dropout_rate, edge_dropout_px): with probability
// rate * exp(-d / px) at Chebyshev distance d from the nearest edge pixel,
// up to d = 4 edge_dropout_px (beyond, the probability is below 2% of the rate).
void drop_near_edges(DepthImage& depth, const std::vector<uint8_t>& edges, double rate, double px, Rng& rng) {
  const int W = depth.width, H = depth.height;
  const int cap = static_cast<int>(std::ceil(4 * px));
  std::vector<int> dist(depth.z.size(), -1);
  std::vector<size_t> frontier, next;
  for (size_t p = 0; p < edges.size(); ++p)
    if (edges[p]) dist[p] = 0, frontier.push_back(p);
  for (int k = 1; k <= cap && !frontier.empty(); ++k) {
    next.clear();
    for (size_t p : frontier) {
      const int u = static_cast<int>(p % W), v = static_cast<int>(p / W);
      for (int dv = -1; dv <= 1; ++dv)
        for (int du = -1; du <= 1; ++du) {
          const int uu = u + du, vv = v + dv;
          if (uu < 0 || vv < 0 || uu >= W || vv >= H) continue;
          const size_t q = static_cast<size_t>(vv) * W + uu;
          if (dist[q] >= 0) continue;
          dist[q] = k;
          next.push_back(q);
        }
    }
    frontier.swap(next);
  }
  for (size_t p = 0; p < depth.z.size(); ++p)
    if (dist[p] >= 0 && valid_depth(depth.z[p]) && rng.bernoulli(rate * std::exp(-dist[p] / px))) depth.z[p] = 0.f;
}

// The model at another focal length than the one its pixel-unit fields
// were fitted at (StructuredLightNoise::reference_fx): f * b stays, so the
// disparity-unit fields and the depth noise stay; the window and edge widths
// scale with the focal length; the projector keeps its real baseline.
StructuredLightNoise at_focal_length(const StructuredLightNoise& s, double fx) {
  if (!(s.reference_fx > 0) || s.reference_fx == fx) return s;
  const double k = fx / s.reference_fx;
  StructuredLightNoise a = s;
  a.baseline_mm = s.baseline_mm / k;
  a.smoothing_radius_px = static_cast<int>(std::lround(s.smoothing_radius_px * k));
  a.edge_bleed_px = s.edge_bleed_px * k;
  a.edge_dropout_px = s.edge_dropout_px * k;
  return a;
}

void apply_structured_light(DepthImage& depth, const std::vector<Vec3f>& normals, const Intrinsics& K,
                            const StructuredLightNoise& fitted, Rng& rng) {
  const StructuredLightNoise s = at_focal_length(fitted, K.fx);
  const bool edge_effects = s.edge_bleed_px > 0 || s.edge_dropout_rate > 0;
  DepthImage truth;
  if (edge_effects) truth = depth;
  apply_structured_light_core(depth, normals, K, s, fitted.baseline_mm, rng);
  if (!edge_effects) return;
  if (s.edge_bleed_px > 0) bleed_edges(depth, truth, s.edge_bleed_px, rng);
  if (s.edge_dropout_rate > 0) drop_near_edges(depth, depth_edges(truth), s.edge_dropout_rate, s.edge_dropout_px, rng);
}

// Disparity noise, smoothing, quantization, shadows and grazing angles.
void apply_structured_light_core(DepthImage& depth, const std::vector<Vec3f>& normals, const Intrinsics& K,
                                 const StructuredLightNoise& s, double shadow_baseline_mm, Rng& rng) {
  const int W = depth.width, H = depth.height;
  const size_t N = depth.z.size();
  const double fb = K.fx * s.baseline_mm;
  // Per-thread scratch, reused from image to image (no fresh pages each
  // time). d_cmp: the true disparity of a measured pixel, +inf elsewhere (it
  // then fails every same-surface test); d_noisy: 0 where not measured.
  // Every element is written below (no fill first).
  thread_local std::vector<double> d_cmp, d_noisy;
  thread_local std::vector<uint8_t> ok;
  d_cmp.resize(N);
  d_noisy.resize(N);
  ok.resize(N);
  std::vector<uint8_t> shadow;
  if (s.shadows) shadow = projector_shadow_mask(depth, K, shadow_baseline_mm);
  const std::vector<uint8_t> grazing = grazing_mask(depth, normals, K, s.max_incidence_deg);
  for (size_t px = 0; px < N; ++px) {
    ok[px] = valid_depth(depth.z[px]) && !grazing[px] && !(s.shadows && shadow[px]);
    d_cmp[px] = ok[px] ? fb / depth.z[px] : std::numeric_limits<double>::infinity();
  }
  for (size_t px = 0; px < N; ++px)
    d_noisy[px] = ok[px] ? d_cmp[px] + rng.normal(0.0, s.disparity_sigma_px) : 0.0;
  const int r = std::max(0, s.smoothing_radius_px);
  // An infinite edge (average every measured pixel) as the largest finite
  // one: the +inf of unmeasured pixels must still fail the test.
  const double edge = std::min(s.smoothing_edge_px, std::numeric_limits<double>::max());
  // Each measured pixel: the mean noisy disparity of the window's pixels of
  // the same surface, summed in row-major window order; a pixel left out
  // adds +0.0, which leaves the sum as it is, bit for bit. A sum is a chain
  // of dependent additions: neighbouring pixels are summed side by side in
  // SIMD lanes (window_sums.h) so that their chains overlap, each in its own
  // order.
  thread_local std::vector<double> row_sum, row_count;
  row_sum.resize(static_cast<size_t>(W));
  row_count.resize(static_cast<size_t>(W));
  for (int v = 0; v < H; ++v) {
    const int v0 = std::max(0, v - r), v1 = std::min(H - 1, v + r);
    const size_t line = static_cast<size_t>(v) * W;
    // One pixel's sums on their own (the windows cut by the border; every
    // pixel without x86 SIMD).
    const auto single = [&](int u) {
      const size_t px = line + u;
      if (!ok[px]) return;
      const int u0 = std::max(0, u - r), u1 = std::min(W - 1, u + r);
      const double centre = d_cmp[px];
      double sum = 0.0;
      int count = 0;
      for (int vv = v0; vv <= v1; ++vv) {
        const size_t row = static_cast<size_t>(vv) * W;
        for (int uu = u0; uu <= u1; ++uu) {
          const bool same = !(std::abs(d_cmp[row + uu] - centre) > edge);
          sum += same ? d_noisy[row + uu] : 0.0;
          count += same;
        }
      }
      row_sum[u] = sum;
      row_count[u] = count;  // >= 1: the pixel itself
    };
    int u = 0;
    for (; u < std::min(r, W); ++u) single(u);
    u = window_sums(WindowSumRow{d_cmp.data(), d_noisy.data(), line, W, v0, v1, r, edge}, u, row_sum.data(),
                    row_count.data());
    for (; u < W; ++u) single(u);
    depths_from_sums(row_sum.data(), row_count.data(), ok.data() + line, 0, W, s.disparity_step_px, fb,
                     depth.z.data() + line);
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

}  // namespace

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
