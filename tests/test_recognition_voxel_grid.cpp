// The voxel grid (recognition/preprocess/voxel_grid.h) against a plain
// reference written from its header's definition: cells floor(p / leaf) or
// floor(p * (1 / leaf)) per axis, non-finite points skipped, cells in key
// order (z, y, x or x, y, z), each cell's centroid, normal, curvature and
// pixel accumulated in input order, normal clusters within a cell. Every
// option, random clouds with points on cell borders, duplicates, NaN and
// infinite points, coordinates spanning more than 2^21 cells (the grid's
// triple-key path), and a rendered table frame: the same bits.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <numeric>
#include <vector>

#include "core/hash.h"
#include "core/random.h"
#include "recognition/preprocess/preprocess.h"
#include "recognition/preprocess/voxel_grid.h"
#include "recognition/preprocess/voxel_keys.h"
#include "test_recognition_pipeline_util.h"

namespace {

using pb::PointSet;
using pb::Vec3;
using pb::Vec3f;
using pb::VoxelGridOptions;

using Key = std::array<int64_t, 3>;

// Each cell's (or normal cluster's) members, in key order, members in input order.
std::vector<std::vector<int>> reference_groups(const PointSet& in, const VoxelGridOptions& o) {
  const double inv = 1.0 / o.leaf_mm;
  const bool divide = o.cell_index == VoxelGridOptions::CellIndex::kDivide;
  auto cell = [&](float v) { return static_cast<int64_t>(std::floor(divide ? v / o.leaf_mm : v * inv)); };
  const bool zyx = o.order == VoxelGridOptions::Order::kZYX;
  std::map<Key, std::vector<int>> cells;
  for (size_t i = 0; i < in.points.size(); ++i) {
    const Vec3f& p = in.points[i];
    if (!p.allFinite()) continue;
    cells[Key{cell(p[zyx ? 2 : 0]), cell(p[1]), cell(p[zyx ? 0 : 2])}].push_back(static_cast<int>(i));
  }
  const bool cluster = in.normals.size() == in.points.size() && o.normal_cluster_deg > 0;
  const float min_cos = static_cast<float>(std::cos(o.normal_cluster_deg * M_PI / 180.0));
  std::vector<std::vector<int>> groups;
  for (const auto& [key, members] : cells) {
    if (!cluster) {
      groups.push_back(members);
      continue;
    }
    std::vector<std::vector<int>> cl;
    for (const int i : members) {
      bool placed = false;
      for (auto& c : cl)
        if (in.normals[static_cast<size_t>(c[0])].dot(in.normals[static_cast<size_t>(i)]) >= min_cos) {
          c.push_back(i);
          placed = true;
          break;
        }
      if (!placed) cl.push_back({i});
    }
    for (auto& c : cl) groups.push_back(c);
  }
  return groups;
}

Vec3 mean_of(const PointSet& in, const std::vector<int>& g) {
  Vec3 s = Vec3::Zero();
  for (const int i : g) s += in.points[static_cast<size_t>(i)].cast<double>();
  return s / static_cast<double>(g.size());
}

PointSet reference_downsample(const PointSet& in, const VoxelGridOptions& o) {
  const size_t n = in.points.size();
  const bool has_n = in.normals.size() == n, has_c = in.curvature.size() == n, has_px = in.pixel.size() == n;
  PointSet out;
  for (const auto& g : reference_groups(in, o)) {
    const Vec3 c = mean_of(in, g);
    if (has_n) {
      Vec3 s = Vec3::Zero();
      for (const int i : g) s += in.normals[static_cast<size_t>(i)].cast<double>();
      const double l = s.norm();
      if (o.drop_cancelled_normals > 0 && !(l > o.drop_cancelled_normals * static_cast<double>(g.size()))) continue;
      out.normals.push_back(l > 0 ? Vec3f((s / l).cast<float>()) : in.normals[static_cast<size_t>(g[0])]);
    }
    out.points.push_back(c.cast<float>());
    if (has_c) {
      double s = 0;
      for (const int i : g) s += in.curvature[static_cast<size_t>(i)];
      out.curvature.push_back(static_cast<float>(s / static_cast<double>(g.size())));
    }
    if (has_px) {
      double best = std::numeric_limits<double>::infinity();
      int px = -1;
      for (const int i : g) {
        const double d = (in.points[static_cast<size_t>(i)].cast<double>() - c).squaredNorm();
        const int q = in.pixel[static_cast<size_t>(i)];
        if (d < best || (d == best && q < px)) {
          best = d;
          px = q;
        }
      }
      out.pixel.push_back(px);
    }
  }
  return out;
}

std::vector<int> reference_nearest(const PointSet& in, const VoxelGridOptions& o) {
  VoxelGridOptions plain = o;
  plain.normal_cluster_deg = 0;
  std::vector<int> out;
  for (const auto& g : reference_groups(in, plain)) {
    const Vec3 c = mean_of(in, g);
    double best = std::numeric_limits<double>::max();
    int idx = -1;
    for (const int i : g) {  // ties: the lower index
      const double d = (in.points[static_cast<size_t>(i)].cast<double>() - c).squaredNorm();
      if (d < best) {
        best = d;
        idx = i;
      }
    }
    out.push_back(idx);
  }
  return out;
}

template <class T>
bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

void expect_same(const PointSet& got, const PointSet& want, const std::string& what) {
  EXPECT_TRUE(same_bits(got.points, want.points)) << what << ": points (" << got.size() << " vs " << want.size() << ")";
  EXPECT_TRUE(same_bits(got.normals, want.normals)) << what << ": normals";
  EXPECT_TRUE(same_bits(got.curvature, want.curvature)) << what << ": curvature";
  EXPECT_EQ(got.pixel, want.pixel) << what << ": pixels";
}

// A random cloud of n points in a cube of side `extent` around `centre`:
// a fifth snapped to multiples of `leaf` (cell borders), some repeated (ties
// of the nearest point), a few NaN or infinite; random unit normals with
// some opposite pairs (cancelling sums), curvatures, shuffled pixels.
PointSet random_cloud(pb::Rng& rng, int n, double extent, double centre, double leaf) {
  PointSet ps;
  for (int i = 0; i < n; ++i) {
    Vec3f p(static_cast<float>(rng.uniform(centre - extent / 2, centre + extent / 2)),
            static_cast<float>(rng.uniform(-extent / 2, extent / 2)),
            static_cast<float>(rng.uniform(centre - extent / 2, centre + extent / 2)));
    const double r = rng.uniform();
    if (r < 0.2) p = (p.cast<double>() / leaf).array().round().matrix().cast<float>() * static_cast<float>(leaf);
    if (r > 0.9 && i > 0) p = ps.points[static_cast<size_t>(rng.uniform_int(0, i - 1))];
    if (r > 0.99) p[rng.uniform_int(0, 2)] = rng.bernoulli(0.5) ? std::numeric_limits<float>::quiet_NaN()
                                                                 : -std::numeric_limits<float>::infinity();
    ps.points.push_back(p);
    Vec3f nrm(static_cast<float>(rng.normal()), static_cast<float>(rng.normal()), static_cast<float>(rng.normal()));
    nrm.normalize();
    if (rng.uniform() < 0.1 && i > 0) nrm = -ps.normals.back();
    ps.normals.push_back(nrm);
    ps.curvature.push_back(static_cast<float>(rng.uniform(0, 0.3)));
  }
  ps.pixel.resize(static_cast<size_t>(n));
  std::iota(ps.pixel.begin(), ps.pixel.end(), 0);
  for (int i = n - 1; i > 0; --i)
    std::swap(ps.pixel[static_cast<size_t>(i)], ps.pixel[static_cast<size_t>(rng.uniform_int(0, i))]);
  return ps;
}

TEST(VoxelGrid, EqualsThePlainReferenceForEveryOption) {
  pb::Rng rng(21);
  int cases = 0;
  // (extent, centre, leaf): 2e-3 mm over 2 m gives packed keys of more than
  // 32 bits; 1e-3 mm over 4 m spans more than 2^21 cells (the triple keys).
  for (const auto& [extent, centre, leaf] :
       {std::array<double, 3>{400, 0, 10}, std::array<double, 3>{300, 1500, 7.3}, std::array<double, 3>{50, -20, 0.37},
        std::array<double, 3>{2000, 0, 2e-3}, std::array<double, 3>{4000, 0, 1e-3}}) {
    const PointSet full = random_cloud(rng, 3000, extent, centre, leaf);
    for (const auto order : {VoxelGridOptions::Order::kZYX, VoxelGridOptions::Order::kXYZ})
      for (const auto index : {VoxelGridOptions::CellIndex::kTimesInverse, VoxelGridOptions::CellIndex::kDivide})
        for (const int fields : {0, 1, 2, 3}) {  // without / with normals and curvature
          PointSet in = full;
          if (!(fields & 1)) in.normals.clear();
          if (!(fields & 2)) in.curvature.clear();
          for (const double drop : {0.0, 0.3})
            for (const double cluster : {0.0, 30.0}) {
              VoxelGridOptions o;
              o.leaf_mm = leaf;
              o.order = order;
              o.cell_index = index;
              o.drop_cancelled_normals = drop;
              o.normal_cluster_deg = cluster;
              const std::string what = "extent " + std::to_string(extent) + " leaf " + std::to_string(leaf) +
                                       " order " + std::to_string(static_cast<int>(order)) + " index " +
                                       std::to_string(static_cast<int>(index)) + " fields " + std::to_string(fields) +
                                       " drop " + std::to_string(drop) + " cluster " + std::to_string(cluster);
              expect_same(pb::voxel_downsample(in, o), reference_downsample(in, o), what);
              EXPECT_EQ(pb::voxel_nearest_points(in, o), reference_nearest(in, o)) << what;
              ++cases;
            }
        }
  }
  EXPECT_EQ(cases, 5 * 2 * 2 * 4 * 2 * 2);
  // The degenerate inputs: no points, every point non-finite, no leaf.
  PointSet nan;
  nan.points.assign(5, Vec3f::Constant(std::numeric_limits<float>::quiet_NaN()));
  nan.pixel = {0, 1, 2, 3, 4};
  EXPECT_TRUE(pb::voxel_downsample(nan, {10.0}).empty());
  EXPECT_TRUE(pb::voxel_nearest_points(nan, {10.0}).empty());
  EXPECT_TRUE(pb::voxel_downsample(PointSet{}, {10.0}).empty());
  EXPECT_EQ(pb::voxel_downsample(nan, {0.0}).size(), 5u);  // leaf 0: the input as is
}

// The four-point kernels equal the one-point loops: the box of the finite
// points (any n, NaN and infinities in single coordinates), and the packed
// keys for both orders and both cell index forms (with AVX2 where the CPU
// has it; elsewhere both sides run the same loop), cell borders included.
TEST(VoxelGrid, FourPointKernelsEqualTheOnePointLoops) {
  namespace detail = pb::detail;
  pb::Rng rng(33);
  size_t compared = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const int n = trial < 40 ? trial % 10 : rng.uniform_int(10, 2000);
    const double leaf = trial % 3 == 0 ? 10.0 : rng.uniform(0.5, 30);
    const PointSet ps = random_cloud(rng, n, rng.uniform(10, 3000), rng.uniform(-500, 2000), leaf);
    float lo[3], hi[3];
    const bool any = detail::finite_box(ps.points.data(), ps.points.size(), lo, hi);
    constexpr float kInf = std::numeric_limits<float>::infinity();
    float want_lo[3] = {kInf, kInf, kInf}, want_hi[3] = {-kInf, -kInf, -kInf};
    for (const Vec3f& p : ps.points)
      if (p.allFinite())
        for (int d = 0; d < 3; ++d) {
          want_lo[d] = std::min(want_lo[d], p[d]);
          want_hi[d] = std::max(want_hi[d], p[d]);
        }
    ASSERT_EQ(any, want_lo[0] <= want_hi[0]) << "trial " << trial;
    if (!any) continue;
    for (int d = 0; d < 3; ++d) {
      ASSERT_EQ(lo[d], want_lo[d]) << "trial " << trial << " axis " << d;
      ASSERT_EQ(hi[d], want_hi[d]) << "trial " << trial << " axis " << d;
    }
    for (const bool zyx : {true, false})
      for (const bool divide : {false, true}) {
        detail::PackedGrid g;
        g.leaf = leaf;
        g.divide = divide;
        g.int32_cells = true;
        int width[3];
        for (int f = 0; f < 3; ++f) {
          g.axis[f] = f == 1 ? 1 : (zyx == (f == 0) ? 2 : 0);
          const int a = g.axis[f];
          auto cell = [&](float v) { return detail::floor_to_int(divide ? v / leaf : v * (1.0 / leaf)); };
          g.lo[f] = cell(lo[a]);
          width[f] = 0;
          while (width[f] < 63 && (cell(hi[a]) - g.lo[f]) >> width[f]) ++width[f];
        }
        g.shift[0] = width[1] + width[2];
        g.shift[1] = width[2];
        std::vector<uint64_t> best(ps.size()), scalar(ps.size());
        detail::packed_cell_keys(ps.points.data(), ps.size(), g, best.data(), detail::KeyIsa::best);
        detail::packed_cell_keys(ps.points.data(), ps.size(), g, scalar.data(), detail::KeyIsa::scalar);
        ASSERT_EQ(best, scalar) << "trial " << trial << " zyx " << zyx << " divide " << divide;
        for (size_t i = 0; i < ps.size(); ++i)
          EXPECT_EQ(scalar[i] == detail::kNoCell, !ps.points[i].allFinite()) << "trial " << trial << " point " << i;
        compared += ps.size();
      }
  }
  EXPECT_GT(compared, 1000000u);
}

// A rendered table frame, range-cut as the scene preprocessing cuts it
// (pixels in image order): every pixel's point at the scene's voxel sizes;
// with the image's width given and without, with pixels out of image order
// and with pixels unknown (-1), which each cell's nearest pixel must handle.
TEST(VoxelGrid, EqualsThePlainReferenceOnATableFrame) {
  const pb::Mesh mesh = pbtest::make_l_block();
  const pbtest::TableScene scene = pbtest::render_table_scene(mesh);
  const pb::OrganizedCloud cloud = pb::OrganizedCloud::from_depth(scene.depth, scene.K);
  PointSet in;
  for (size_t i = 0; i < cloud.points.size(); ++i)
    if (cloud.points[i].allFinite()) {
      in.points.push_back(cloud.points[i]);
      in.pixel.push_back(static_cast<int>(i));
    }
  ASSERT_GT(in.size(), 10000u);
  PointSet organized = in;
  organized.source_width = cloud.width;
  organized.source_height = cloud.height;
  PointSet shuffled = organized;  // two halves swapped: pixels fall back once
  std::rotate(shuffled.points.begin(), shuffled.points.begin() + shuffled.size() / 2, shuffled.points.end());
  std::rotate(shuffled.pixel.begin(), shuffled.pixel.begin() + shuffled.size() / 2, shuffled.pixel.end());
  PointSet unknown = organized;  // points without a pixel (-1): first, and from the middle on
  unknown.pixel[0] = -1;
  PointSet unknown_later = organized;
  for (size_t i = unknown_later.size() / 2; i < unknown_later.size(); i += 7) unknown_later.pixel[i] = -1;
  for (const double leaf : {3.0, 5.0, 10.0, 20.0})
    for (const PointSet* ps : {&in, &organized, &shuffled, &unknown, &unknown_later}) {
      const VoxelGridOptions o{leaf};
      const PointSet got = pb::voxel_downsample(*ps, o);
      EXPECT_GT(got.size(), 100u);
      expect_same(got, reference_downsample(*ps, o),
                  "table frame, leaf " + std::to_string(leaf) + ", width " + std::to_string(ps->source_width) +
                      (ps == &shuffled ? ", halves swapped" : ps == &in || ps == &organized ? "" : ", pixels -1"));
    }
}

// The whole scene preprocessing (range cut, grid, RANSAC plane, normals)
// of a rendered table frame, bit for bit as recorded before the range cut,
// the grid and the plane scoring were rewritten for speed: a change of any
// of them that moves a bit changes the fingerprint (on this toolchain:
// x86-64 without FMA contraction). Also with the veil filter and
// two planes.
TEST(VoxelGrid, ScenePreprocessingKeepsItsFingerprint) {
  const pb::Mesh mesh = pbtest::make_l_block();
  const pbtest::TableScene scene = pbtest::render_table_scene(mesh);
  const pb::OrganizedCloud cloud = pb::OrganizedCloud::from_depth(scene.depth, scene.K);
  pb::Fnv1a64 h;
  auto add = [&](const PointSet& ps) {
    h.bytes(ps.points.data(), ps.size() * sizeof(Vec3f));
    h.bytes(ps.normals.data(), ps.normals.size() * sizeof(Vec3f));
    h.bytes(ps.curvature.data(), ps.curvature.size() * sizeof(float));
    EXPECT_TRUE(ps.pixel.empty()) << "a scene's points carry no pixel (preprocess.h)";
  };
  pb::PreprocessSettings s;
  const PointSet a = pb::preprocess_scene(cloud, s, 5);
  ASSERT_GT(a.size(), 50u);
  add(a);
  s.veil_angle_deg = 10;
  s.max_planes = 2;
  s.min_plane_fraction = 0.05;
  s.voxel_mm = 4;
  const PointSet b = pb::preprocess_scene(cloud, s, 7);
  EXPECT_GT(b.size(), a.size());
  add(b);
  s.plane_sample_points = 0;
  const PointSet c = pb::preprocess_scene(cloud, s, 7);
  EXPECT_GT(c.size(), a.size());
  add(c);
  // The points, normals and curvature only: a scene's points carry no
  // pixel (preprocess.h).
  EXPECT_EQ(pb::hex16(h.digest()), "936aac334f1c9f65");
}

}  // namespace
