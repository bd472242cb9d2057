// Procedural models: closed, outward-oriented meshes of the documented sizes,
// origin at the bounding box centre, up = +z.
#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "core/error.h"
#include "models/procedural.h"

using namespace pb;

namespace {

// Every undirected edge used by exactly two faces, once in each direction.
::testing::AssertionResult closed_and_oriented(const Mesh& m) {
  std::map<std::pair<int, int>, int> directed;
  for (const auto& f : m.faces) {
    if (f[0] == f[1] || f[1] == f[2] || f[0] == f[2]) return ::testing::AssertionFailure() << "degenerate face";
    for (int k = 0; k < 3; ++k) directed[{f[k], f[(k + 1) % 3]}]++;
  }
  for (const auto& [e, n] : directed) {
    if (n != 1) return ::testing::AssertionFailure() << "edge " << e.first << "-" << e.second << " used " << n << " times";
    auto it = directed.find({e.second, e.first});
    if (it == directed.end())
      return ::testing::AssertionFailure() << "edge " << e.first << "-" << e.second << " has one face only";
  }
  return ::testing::AssertionSuccess();
}

double volume(const Mesh& m) {
  double v = 0;
  for (const auto& f : m.faces)
    v += m.vertices[f[0]].cast<double>().dot(m.vertices[f[1]].cast<double>().cross(m.vertices[f[2]].cast<double>())) / 6;
  return v;
}

Vec3 extent(const Mesh& m) { return (m.bounds().max() - m.bounds().min()).cast<double>(); }
Vec3 centre(const Mesh& m) { return m.bounds().center().cast<double>(); }

}  // namespace

TEST(Procedural, BoxExactSizeVolumeAndClosed) {
  const Mesh b = make_box(120, 80, 60);
  EXPECT_TRUE(closed_and_oriented(b));
  EXPECT_NEAR(volume(b), 120.0 * 80 * 60, 1e-3);
  EXPECT_TRUE(extent(b).isApprox(Vec3(120, 80, 60)));
  EXPECT_LT(centre(b).norm(), 1e-4);
  EXPECT_NEAR(b.diameter(), std::sqrt(120.0 * 120 + 80 * 80 + 60 * 60), 1e-3);
}

TEST(Procedural, CylinderSizeAndVolume) {
  const Mesh c = make_cylinder(35, 120, 48);
  EXPECT_TRUE(closed_and_oriented(c));
  EXPECT_NEAR(extent(c).x(), 70, 1e-3);
  EXPECT_NEAR(extent(c).z(), 120, 1e-3);
  // Inscribed 48-gon area: n/2 r^2 sin(2 pi / n).
  EXPECT_NEAR(volume(c), 24 * 35.0 * 35 * std::sin(2 * M_PI / 48) * 120, 1.0);
  EXPECT_NEAR(c.diameter(), std::sqrt(70.0 * 70 + 120 * 120), 1e-3);
}

TEST(Procedural, MilkCartonIsAOneLitreGableTop) {
  const Mesh m = make_milk_carton();
  EXPECT_TRUE(closed_and_oriented(m));
  EXPECT_NEAR(extent(m).x(), 70, 1e-3);
  EXPECT_NEAR(extent(m).y(), 70, 1e-3);
  EXPECT_NEAR(extent(m).z(), 240, 1e-3);  // 195 body + 33 roof + 12 fin
  EXPECT_LT(centre(m).norm(), 1e-4);
  // The body: every vertex below the roof line has |x| = |y| = 35 (box walls)
  // and the roof starts 195 mm above the bottom.
  const float zmin = m.bounds().min().z();
  int eaves = 0;
  for (const auto& v : m.vertices)
    if (std::abs(v.z() - (zmin + 195)) < 1e-3 && std::abs(std::abs(v.y()) - 35) < 1e-3) ++eaves;
  EXPECT_EQ(eaves, 4);
  // Volume: 70 * 70 * 195 body (955.5 ml) + roof prism + fin: a bit over 1 litre.
  const double body = 70.0 * 70 * 195;
  EXPECT_GT(volume(m), body);
  EXPECT_NEAR(volume(m), body + 70 * (0.5 * (70 + 4) * 33 + 4 * 12), 1.0);
  EXPECT_NEAR(m.diameter(), std::sqrt(70.0 * 70 + 37 * 37 + 240 * 240), 1e-3);
}

TEST(Procedural, Ls5IsNearSymmetricAboutZ) {
  const Mesh m = make_ls5();
  // The head and the connector are two closed parts.
  EXPECT_TRUE(closed_and_oriented(m));
  EXPECT_GT(volume(m), 0);
  EXPECT_NEAR(extent(m).x(), 120, 1e-3);
  EXPECT_NEAR(extent(m).y(), 120, 0.1);
  EXPECT_NEAR(extent(m).z(), 145, 1e-3);
  EXPECT_LT(centre(m).head<2>().norm(), 0.1);
  // The connector is the only vertex set beyond the head radius above the flange.
  const float zmin = m.bounds().min().z();
  int outside = 0;
  for (const auto& v : m.vertices) {
    const double r = std::hypot(v.x(), v.y());
    if (v.z() > zmin + 25 && r > 50.5) {
      ++outside;
      EXPECT_GT(v.x(), 55) << v.transpose();  // on the +x side only
    }
  }
  EXPECT_EQ(outside, 4);
}

TEST(Procedural, BoletusStemAndCap) {
  const Mesh m = make_boletus();
  EXPECT_TRUE(closed_and_oriented(m));
  EXPECT_GT(volume(m), 0);
  EXPECT_NEAR(extent(m).x(), 106, 0.1);
  EXPECT_NEAR(extent(m).z(), 110, 1e-3);
  // Stem narrower than the cap: the widest ring below mid-height is the bulb.
  const float zmin = m.bounds().min().z();
  double stem = 0, cap = 0;
  for (const auto& v : m.vertices) {
    const double r = std::hypot(v.x(), v.y());
    (v.z() < zmin + 55 ? stem : cap) = std::max(v.z() < zmin + 55 ? stem : cap, r);
  }
  EXPECT_NEAR(stem, 25, 1e-3);
  EXPECT_NEAR(cap, 53, 1e-3);
}

TEST(Procedural, PalletIsAEurPallet) {
  const Mesh m = make_pallet();
  EXPECT_TRUE(closed_and_oriented(m));
  EXPECT_TRUE(extent(m).isApprox(Vec3(1200, 800, 144), 1e-6));
  EXPECT_LT(centre(m).norm(), 1e-3);
  EXPECT_EQ(m.faces.size(), 20u * 12);  // 3 bottom boards, 9 blocks, 3 cross boards, 5 deck boards
  // Slatted: a vertical ray through a gap between deck boards at the centre
  // line hits no deck board (no face spans y in the 41.25 mm gap at the top).
  const double gap_y = -400 + 145 + 20;  // inside the first gap
  for (const auto& f : m.faces) {
    bool top = true;
    float ymin = 1e9, ymax = -1e9;
    for (int k = 0; k < 3; ++k) {
      top = top && m.vertices[f[k]].z() > 71.9;
      ymin = std::min(ymin, m.vertices[f[k]].y());
      ymax = std::max(ymax, m.vertices[f[k]].y());
    }
    if (top) EXPECT_FALSE(ymin < gap_y && ymax > gap_y) << "a top face covers the gap";
  }
}

TEST(Procedural, KindsAndErrors) {
  for (const auto& k : procedural_kinds()) EXPECT_FALSE(make_procedural(k).empty()) << k;
  EXPECT_TRUE(extent(make_procedural("box:10x20x30")).isApprox(Vec3(10, 20, 30)));
  EXPECT_NEAR(extent(make_procedural("cylinder:580x880")).z(), 880, 1e-3);
  EXPECT_NEAR(extent(make_procedural("cylinder:580x880")).x(), 580, 1e-3);
  for (const char* bad : {"spaceship", "box:10x20", "box:10x-2x3", "cylinder:axb", "ls5:3", "box:"}) {
    try {
      make_procedural(bad);
      ADD_FAILURE() << bad << " accepted";
    } catch (const InputError& e) {
      EXPECT_EQ(e.field(), "source") << bad;
    }
  }
}
