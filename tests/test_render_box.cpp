// Noise off: a box at a known pose back-projects onto its surface; labels and
// depth of two overlapping boxes follow the nearer one; normals; several
// renderers in several threads give the same images as one.
#include <gtest/gtest.h>

#include <cmath>
#include <thread>

#include "core/error.h"
#include "core/rotation.h"
#include "render/renderer.h"
#include "test_render_util.h"

using namespace pb;

namespace {

// Distance of a model-frame point to the surface of a box with half extents h.
double box_surface_distance(const Vec3& p, const Vec3& h) {
  const Vec3 q = p.cwiseAbs() - h;
  const double outside = q.cwiseMax(0.0).norm();
  const double inside = std::min(q.maxCoeff(), 0.0);
  return std::abs(outside + inside);
}

Pose box_pose() {
  Pose T;
  T.R = axis_angle(Vec3(1, 2, 0.5).normalized(), 0.7);
  T.t = Vec3(40, -30, 900);
  return T;
}

// The analytic label at a pixel if it is the same over a small
// neighbourhood (else -2: on a silhouette, not checked).
int robust_label(const Intrinsics& K, const std::vector<std::pair<Pose, Vec3>>& boxes, double u, double v,
                 double* depth) {
  int label = -2;
  for (double du : {-0.05, 0.0, 0.05})
    for (double dv : {-0.05, 0.0, 0.05}) {
      double best = std::numeric_limits<double>::infinity();
      int l = -1;
      for (size_t i = 0; i < boxes.size(); ++i) {
        const double z = pbtest::box_depth(K, boxes[i].first, boxes[i].second, u + du, v + dv);
        if (z < best) best = z, l = static_cast<int>(i);
      }
      if (du == 0.0 && dv == 0.0) *depth = best;
      if (label == -2) label = l;
      else if (label != l) return -2;
    }
  return label;
}

}  // namespace

TEST(RenderBox, BackProjectedPixelsLieOnTheBoxSurface) {
  const Intrinsics K = Intrinsics::from_fov(640, 480, 59, 46);
  RenderSettings s;
  s.normals = true;
  DepthRenderer r(K, s);
  const Vec3 half(60, 45, 30);
  const Mesh box = pbtest::make_box(60, 45, 30);
  const Pose T = box_pose();
  const RenderOutput out = r.render({{&box, T, 3}});
  const Pose T_box_cam = T.inverse();
  size_t n = 0, wrong_coverage = 0;
  double worst = 0, worst_normal = 0;
  for (int v = 0; v < K.height; ++v)
    for (int u = 0; u < K.width; ++u) {
      const float z = out.depth.at(u, v);
      const size_t px = static_cast<size_t>(v) * K.width + u;
      double z_true;
      const int hit = robust_label(K, {{T, half}}, u, v, &z_true);
      if (hit != -2 && (hit == 0) != (z > 0)) ++wrong_coverage;
      if (z <= 0) {
        EXPECT_EQ(out.labels[px], -1);
        EXPECT_EQ(out.normals[px].norm(), 0.f);
        continue;
      }
      ++n;
      EXPECT_EQ(out.labels[px], 3);
      const Vec3 p = T_box_cam * K.backproject(u, v, z);
      worst = std::max(worst, box_surface_distance(p, half));
      // The normal is the box face's normal (the axis where p touches it),
      // in the camera frame, facing the camera.
      const Vec3 q = p.cwiseAbs() - half;
      int axis;
      q.maxCoeff(&axis);
      Vec3 nm = Vec3::Zero();
      nm[axis] = p[axis] > 0 ? 1 : -1;
      const Vec3 nc = T.R * nm;
      worst_normal = std::max(worst_normal, (out.normals[px].cast<double>() - nc).norm());
      EXPECT_LT(out.normals[px].cast<double>().dot(K.backproject(u, v, 1.0)), 0.0);
    }
  std::printf("box: %zu pixels, max distance to surface %.6f mm, max normal error %.2e\n", n, worst,
              worst_normal);
  EXPECT_GT(n, 4000u);
  EXPECT_EQ(wrong_coverage, 0u);
  EXPECT_LT(worst, 0.01);
  EXPECT_LT(worst_normal, 1e-4);
}

TEST(RenderBox, NearerOfTwoOverlappingItemsWins) {
  const Intrinsics K = Intrinsics::from_fov(512, 424, 57, 43);
  DepthRenderer r(K);
  const Vec3 h1(80, 80, 80), h2(40, 60, 20);
  const Mesh b1 = pbtest::make_box(80, 80, 80);
  const Mesh b2 = pbtest::make_box(40, 60, 20);
  Pose T1;
  T1.R = axis_angle(Vec3(0, 1, 0), 0.4);
  T1.t = Vec3(0, 0, 1200);
  Pose T2;
  T2.R = axis_angle(Vec3(1, 0, 1).normalized(), -0.5);
  T2.t = Vec3(60, 30, 1000);  // in front of b1, overlapping it in the image
  const std::vector<std::pair<Pose, Vec3>> boxes = {{T1, h1}, {T2, h2}};
  // Draw the nearer box first and then second: the depth test, not the
  // order, must decide.
  for (int order = 0; order < 2; ++order) {
    const std::vector<RenderItem> items =
        order == 0 ? std::vector<RenderItem>{{&b1, T1, 10}, {&b2, T2, 20}}
                   : std::vector<RenderItem>{{&b2, T2, 20}, {&b1, T1, 10}};
    const RenderOutput out = r.render(items);
    size_t checked = 0, wrong = 0, overlap = 0;
    double worst = 0;
    for (int v = 0; v < K.height; ++v)
      for (int u = 0; u < K.width; ++u) {
        double z_true;
        const int l = robust_label(K, boxes, u, v, &z_true);
        if (l == -2) continue;
        ++checked;
        const int expect = l < 0 ? -1 : (l == 0 ? 10 : 20);
        const int got = out.labels[static_cast<size_t>(v) * K.width + u];
        wrong += got != expect;
        if (expect == 20 && std::isfinite(pbtest::box_depth(K, T1, h1, u, v))) ++overlap;
        if (expect >= 0) worst = std::max(worst, std::abs(out.depth.at(u, v) - z_true));
        else EXPECT_EQ(out.depth.at(u, v), 0.f);
      }
    std::printf("order %d: %zu pixels checked, %zu overlapping, %zu wrong labels, max depth error %.6f\n",
                order, checked, overlap, wrong, worst);
    EXPECT_EQ(wrong, 0u);
    EXPECT_GT(overlap, 1000u);  // the test really exercises the overlap
    EXPECT_LT(worst, 0.01);
    // The labels-only render (the generator's silhouettes and visibility
    // counts) gives the same labels, pixel for pixel.
    EXPECT_TRUE(r.render_labels(items) == out.labels);
  }
  // Without the depth test (items that cover no common pixel): each box
  // alone, and the two boxes moved apart, label their pixels as the full
  // render does; with the boxes overlapping, the depth test is what decides.
  Pose T2_apart = T2;
  T2_apart.t = Vec3(-250, 0, 1000);
  const std::vector<std::vector<RenderItem>> apart = {
      {{&b1, T1, 10}}, {{&b2, T2, 20}}, {{&b2, T2_apart, 20}, {&b1, T1, 10}}};
  for (const auto& items : apart) EXPECT_TRUE(r.render_labels(items, /*overlap=*/false) == r.render(items).labels);
  const std::vector<RenderItem> far_last = {{&b2, T2, 20}, {&b1, T1, 10}};
  EXPECT_FALSE(r.render_labels(far_last, /*overlap=*/false) == r.render(far_last).labels);
}

TEST(RenderBox, RenderersInSeveralThreadsAgreeWithOne) {
  const Intrinsics K = Intrinsics::from_fov(320, 240, 59, 46);
  const Mesh box = pbtest::make_box(50, 70, 30);
  auto pose = [](int i) {
    Pose T;
    T.R = axis_angle(Vec3(1, 1, 0).normalized(), 0.3 * i);
    T.t = Vec3(10.0 * i, -5.0 * i, 700.0 + 50.0 * i);
    return T;
  };
  const int kThreads = 4, kFrames = 6;
  std::vector<std::vector<RenderOutput>> serial(kThreads), parallel(kThreads);
  {
    DepthRenderer r(K, RenderSettings{50, 20000, true});
    for (int t = 0; t < kThreads; ++t)
      for (int f = 0; f < kFrames; ++f) serial[t].push_back(r.render({{&box, pose(t * kFrames + f), t}}));
  }
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t)
    threads.emplace_back([&, t] {
      DepthRenderer r(K, RenderSettings{50, 20000, true});
      for (int f = 0; f < kFrames; ++f) parallel[t].push_back(r.render({{&box, pose(t * kFrames + f), t}}));
    });
  for (auto& th : threads) th.join();
  for (int t = 0; t < kThreads; ++t)
    for (int f = 0; f < kFrames; ++f) {
      EXPECT_GT(serial[t][f].depth.valid_count(), 100u);
      EXPECT_EQ(serial[t][f].depth.z, parallel[t][f].depth.z);
      EXPECT_EQ(serial[t][f].labels, parallel[t][f].labels);
      EXPECT_TRUE(serial[t][f].normals == parallel[t][f].normals);
    }
}

TEST(RenderBox, RendererCanMoveBetweenThreads) {
  const Intrinsics K = Intrinsics::from_fov(160, 120, 59, 46);
  const Mesh box = pbtest::make_box(50, 50, 50);
  Pose T;
  T.t = Vec3(0, 0, 600);
  DepthRenderer r(K);
  const RenderOutput a = r.render({{&box, T, 1}});
  RenderOutput b;
  std::thread th([&] { b = r.render({{&box, T, 1}}); });
  th.join();
  EXPECT_EQ(a.depth.z, b.depth.z);
  EXPECT_GT(a.depth.valid_count(), 100u);
}

TEST(RenderBox, BehindTheCameraIsNotDrawn) {
  const Intrinsics K = Intrinsics::from_fov(160, 120, 59, 46);
  const Mesh box = pbtest::make_box(50, 50, 50);
  Pose T;
  T.t = Vec3(0, 0, -600);
  DepthRenderer r(K);
  EXPECT_EQ(r.render({{&box, T, 1}}).depth.valid_count(), 0u);
}

TEST(RenderBox, BadIntrinsicsAndMeshesAreRejected) {
  Intrinsics K = Intrinsics::from_fov(160, 120, 59, 46);
  K.fx = -1;
  EXPECT_THROW(DepthRenderer r(K), InputError);
  DepthRenderer r(Intrinsics::from_fov(16, 12, 59, 46));
  Mesh m = pbtest::make_box(1, 1, 1);
  m.faces.push_back({0, 1, 99});
  EXPECT_THROW(r.render({{&m, Pose{}, 1}}), std::invalid_argument);
}
