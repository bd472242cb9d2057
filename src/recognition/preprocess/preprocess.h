// Preprocessing (thesis 3.1.1 and 3.2.1): depth -> cloud, range
// cut, voxel grid, dominant plane removal (RANSAC), normals toward the
// viewpoint. The same steps prepare the model's training views.
#pragma once

#include "core/types.h"
#include "core/settings_fields.h"
#include "recognition/cloud.h"

namespace pb {

struct PreprocessSettings {
  double min_range_mm = 100.0;      // points closer than this are dropped
  double max_range_mm = 3000.0;     // far points cut (thesis: "cut by range")
  double veil_angle_deg = 0.0;      // drop mixed ("flying") pixels first: a pixel whose 3D step to an
                                    // 8-neighbour lies within this angle of its viewing ray, with that
                                    // neighbour (a time-of-flight camera's mixed returns at depth edges;
                                    // also the edge's last pixel on each side). 0 = off, as the thesis
                                    // (which describes no such filter). Measured on the Kinect One
                                    // rows: results/thesis/FINDINGS.md
  int pixel_stride = 1;             // a scene's range cut reads every n-th pixel of every n-th row
                                    // (1 = every pixel; training views always read every pixel):
                                    // the voxel grid then averages about n^2 times
                                    // fewer samples per cell. For cells many pixels wide (the
                                    // warehouse's 20 mm: 4-10 pixels where its objects stand, 2-5 m
                                    // away). The veil filter and the plane's noise estimate still
                                    // read every pixel. Measured: results/bench/README.md
  double voxel_mm = 10.0;           // downsampling voxel (Table 4.2: 20 warehouse, 10 table)
  bool remove_plane = true;         // remove the dominant plane (floor / table)
  double plane_threshold_mm = 10.0; // RANSAC inlier distance for the plane
  double plane_noise_factor = 2.0;  // the plane's points are those within max(plane_threshold_mm,
                                    // this x sigma), sigma the depth noise measured in the image
                                    // (second differences along rows: depth_noise_sigma) times the
                                    // median |cos| of the plane's normal to the rays. Removes a noisy
                                    // table whole (25 mm of added noise: 85% of a statue scene's
                                    // points were table left over); 0 = the fixed threshold alone
  int plane_iterations = 200;       // RANSAC iterations, at most
  double plane_probability = 1.0;   // < 1: RANSAC stops once a sample of three inliers of the best
                                    // plane so far was drawn with this probability (PCL's
                                    // RandomSampleConsensus, 0.99 there); 1 = always
                                    // plane_iterations. Measured at 0.99: table frames 3 ms faster,
                                    // Table 4.1 153 of 300 correct instead of 156 (results/bench)
  double min_plane_fraction = 0.2;  // remove a plane only if it holds this fraction (of the points
                                    // before any plane was removed)
  int max_planes = 1;               // dominant planes removed one after the other (thesis: 1, the
                                    // table; the warehouse's floor and wall: 2)
  int plane_sample_points = 5000;   // RANSAC scores its candidate planes on a seeded random subset
                                    // of this many points (0 = all); the winner's inliers are then
                                    // selected among all points and refitted
  bool planes_before_grid = false;  // the planes are found and removed among the range-cut points
                                    // (RANSAC scores its plane_sample_points among them), then the
                                    // voxel grid grids only what is left: on a table frame the table
                                    // is most of the points, so the grid has a fraction of them to
                                    // do (a simulated Astra frame: 8.6-9.9 -> 5.2-6.4 ms). Not the
                                    // default, nor the bench's: over the thesis's table experiments it
                                    // lost robustness where single raw points are noisy or the object's
                                    // foot matters (Figure 4.6's one-view CVFH / CESF: 1951 against
                                    // 1991 of 2400; added noise: 166 against 188 of 1440). false = the
                                    // grid first, then the planes among its voxels (the thesis's
                                    // order, section 3.1.1). Measured: results/bench/README.md
  double normal_radius_mm = 20.0;   // PCA neighbourhood radius for normals
  int normal_max_points = 64;       // a normal's neighbourhood of more points than this is thinned
                                    // evenly (in kd-tree order: spatially stratified) to this many
                                    // before the PCA (0 = every point, as pcl::NormalEstimation)
  bool normal_coarse_support = true;  // a normal's neighbours are the centroids of the cloud voxelized
                                    // at leaf normal_radius_mm x sqrt(pi / normal_max_points) (as
                                    // many cells cover the ball's flat disc), instead of the cloud's
                                    // points thinned, wherever that leaf is at least 1.5 x voxel_mm
                                    // (the warehouse's 0.1 d = 182 mm at 20 mm voxels: a 40 mm leaf;
                                    // not the table's 20 mm at 10 mm voxels); a point with fewer
                                    // than normal_max_points / 4 centroids in its ball takes its own
                                    // neighbours. false = always the cloud's points. Measured:
                                    // results/bench/README.md

  template <class S, class F>
  static void fields(S& s, F& f) {
    f("min_range_mm", s.min_range_mm, fields::nonnegative());
    f("max_range_mm", s.max_range_mm, fields::positive());
    f("veil_angle_deg", s.veil_angle_deg, fields::in_range(0, 90));
    f("pixel_stride", s.pixel_stride, fields::at_least(1));
    f("voxel_mm", s.voxel_mm, fields::length(fields::nonnegative()));
    f("remove_plane", s.remove_plane);
    f("plane_threshold_mm", s.plane_threshold_mm, fields::length(fields::positive()));
    f("plane_noise_factor", s.plane_noise_factor, fields::nonnegative());
    f("plane_iterations", s.plane_iterations, fields::at_least(1));
    f("plane_probability", s.plane_probability, fields::in_range(0, 1));
    f("min_plane_fraction", s.min_plane_fraction, fields::in_range(0, 1));
    f("max_planes", s.max_planes, fields::at_least(0));
    f("plane_sample_points", s.plane_sample_points, fields::at_least(0));
    f("planes_before_grid", s.planes_before_grid);
    f("normal_radius_mm", s.normal_radius_mm, fields::length(fields::positive()));
    f("normal_max_points", s.normal_max_points, fields::at_least(0));
    f("normal_coarse_support", s.normal_coarse_support);
  }
  void validate(const YamlNode& node) const;  // max_range_mm > min_range_mm
  // The leaf of the normals' coarse support (normal_coarse_support), or 0
  // where the cloud's own points serve.
  double normal_support_leaf_mm() const;
};

// Normals by PCA of the neighbours within `radius_mm` (the point included, as
// pcl::NormalEstimation; the project's kd-tree, OpenMP threads per
// omp_get_max_threads(), the same result for any count), flipped toward the
// viewpoint (origin), and the surface variation as curvature. Points whose
// normal cannot be estimated (fewer than 3 neighbours) are dropped, with
// their pixel. max_points > 0: a neighbourhood of more points is thinned
// evenly in tree order to that many (keep_evenly, kdtree.h).
// support_leaf_mm > 0: a point's neighbours are instead the centroids of the
// cloud voxelized at that leaf (a coarse support, built once) within
// `radius_mm`, thinned the same way; a point with fewer than
// max_points / 4 of them (a sparse region, where the fine neighbourhood
// would hardly need thinning) takes the fine neighbourhood as above.
// Preprocessing and CVFH's stable regions (global/regions.cpp) share it.
void radius_normals(PointSet& cloud, double radius_mm, int max_points = 0, double support_leaf_mm = 0);

// Scene preprocessing. Every random choice (RANSAC) draws from `seed`. Its
// points carry no pixel: no later stage reads one, and the voxel grid's pass
// for each cell's nearest pixel cost 0.75 ms of a table frame's 5.95 and 0.9
// of a warehouse frame's 21.0 (results/bench/README.md).
PointSet preprocess_scene(const OrganizedCloud& cloud, const PreprocessSettings& s, uint64_t seed);
// Training view preprocessing: no plane removal (the model is alone).
PointSet preprocess_view(const OrganizedCloud& cloud, const PreprocessSettings& s, uint64_t seed);

}  // namespace pb
