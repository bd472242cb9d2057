#include "report/overlay.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "io/png.h"
#include "render/renderer.h"

namespace pb {

namespace {

// A perceptual-ish colour map (blue -> cyan -> yellow -> red) for depth.
void colormap(double x, uint8_t* rgb) {
  x = std::clamp(x, 0.0, 1.0);
  static const double stops[5][3] = {{48, 18, 59}, {40, 150, 230}, {60, 220, 120}, {250, 200, 40}, {180, 20, 10}};
  const double f = x * 4.0;
  const int i = std::min(3, static_cast<int>(f));
  const double w = f - i;
  for (int c = 0; c < 3; ++c) rgb[c] = static_cast<uint8_t>(std::lround(stops[i][c] * (1 - w) + stops[i + 1][c] * w));
}

}  // namespace

RgbImage depth_overlay(const DepthImage& depth, const Intrinsics& K, const Mesh& mesh, const Pose* est,
                       const Pose* gt) {
  const int w = depth.width, h = depth.height;
  std::vector<float> valid;
  for (float z : depth.z)
    if (z > 0 && std::isfinite(z)) valid.push_back(z);
  double lo = 0, hi = 1;
  if (!valid.empty()) {
    std::sort(valid.begin(), valid.end());
    lo = valid[valid.size() / 100];
    hi = valid[valid.size() - 1 - valid.size() / 100];
    if (hi <= lo) hi = lo + 1;
  }
  std::vector<uint8_t> rgb(static_cast<size_t>(w) * h * 3, 0);
  for (int i = 0; i < w * h; ++i) {
    const float z = depth.z[i];
    if (z > 0 && std::isfinite(z)) colormap((z - lo) / (hi - lo), &rgb[3 * i]);
  }
  DepthRenderer renderer(K);
  auto mask_of = [&](const Pose& T) {
    RenderItem item;
    item.mesh = &mesh;
    item.T_cam_model = T;
    item.label = 1;
    std::vector<char> m(static_cast<size_t>(w) * h, 0);
    if (mesh.faces.empty()) {  // a point-cloud model: its points, 3 x 3 pixels each
      for (const Vec3f& p : mesh.vertices) {
        const Vec3 c = T.R * p.cast<double>() + T.t;
        if (!(c.z() > 0)) continue;
        const Eigen::Vector2d uv = K.project(c);
        for (int dv = -1; dv <= 1; ++dv)
          for (int du = -1; du <= 1; ++du) {
            const double u = std::round(uv.x()) + du, v = std::round(uv.y()) + dv;
            if (u >= 0 && v >= 0 && u < w && v < h) m[static_cast<size_t>(v) * w + static_cast<size_t>(u)] = 1;
          }
      }
      return m;
    }
    const RenderOutput out = renderer.render({item});
    for (size_t i = 0; i < m.size() && i < out.labels.size(); ++i) m[i] = out.labels[i] == 1;
    return m;
  };
  auto outline = [&](const std::vector<char>& m, int x, int y) {
    if (!m[static_cast<size_t>(y) * w + x]) return false;
    const int dx[4] = {1, -1, 0, 0}, dy[4] = {0, 0, 1, -1};
    for (int k = 0; k < 4; ++k) {
      const int u = x + dx[k], v = y + dy[k];
      if (u < 0 || v < 0 || u >= w || v >= h || !m[static_cast<size_t>(v) * w + u]) return true;
    }
    return false;
  };
  if (est) {
    const auto m = mask_of(*est);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const size_t i = static_cast<size_t>(y) * w + x;
        if (!m[i]) continue;
        uint8_t* p = &rgb[3 * i];
        if (outline(m, x, y)) {
          p[0] = 120, p[1] = 255, p[2] = 120;
        } else {
          p[0] = static_cast<uint8_t>(p[0] * 0.4);
          p[1] = static_cast<uint8_t>(p[1] * 0.4 + 255 * 0.6);
          p[2] = static_cast<uint8_t>(p[2] * 0.4);
        }
      }
  }
  if (gt) {
    const auto m = mask_of(*gt);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        if (outline(m, x, y)) {
          uint8_t* p = &rgb[3 * (static_cast<size_t>(y) * w + x)];
          p[0] = 255, p[1] = 0, p[2] = 255;
        }
  }
  return RgbImage{w, h, std::move(rgb)};
}

void write_overlay(const std::string& path, const DepthImage& depth, const Intrinsics& K, const Mesh& mesh,
                   const Pose* est, const Pose* gt) {
  const RgbImage im = depth_overlay(depth, K, mesh, est, gt);
  write_rgb8_png(path, im.width, im.height, im.rgb);
}


}  // namespace pb
