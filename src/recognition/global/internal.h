// Internal pieces of the global pipeline (CVFH, ESF, CESF, OUR-CVFH, CRH),
// shared by the src/recognition/global/*.cpp files. PCL-free: PCL stays in
// the .cpp files that use it (cvfh_pcl.cpp, ourcvfh.cpp, crh.cpp), so the
// others compile without PCL. PCL's ESF and Euclidean clusters, the
// references of ours, are in tests/pcl_reference.
#pragma once

#include <cstdint>
#include <vector>

#include "core/types.h"
#include "recognition/cloud.h"
#include "recognition/global/global.h"

namespace pb::global {

// One global signature: a histogram and the region of the cloud it
// describes, in the frame of the cloud's camera (mm).
struct Signature {
  std::vector<float> hist;
  Vec3f centroid = Vec3f::Zero();  // centroid of the described region
  // Unit "viewing direction" fixing 2 rotational DoF: the negated mean
  // normal of a stable region (CVFH, CESF), or the direction from the camera
  // to the centroid (whole-cluster ESF; CVFH and CESF without stable regions).
  Vec3f axis = Vec3f::UnitZ();
  bool from_normal = false;        // axis is a (negated) mean normal
  // OUR-CVFH: the semi-global reference frame, camera -> frame (mm).
  bool has_rf = false;
  Pose T_rf_cam;
  // CRH spectrum (pcl::CRHEstimation output, 90 values) of the whole cloud
  // about `axis` (empty when not needed).
  std::vector<float> crh;
  int source = -1;                 // training view index, or scene cluster index
};

// --- euclidean.cpp ---
// Euclidean clusters: the connected components of "closer than
// tolerance_mm" (pcl::EuclideanClusterExtraction's clusters, found on a grid
// instead of a radius search per point), those of min_points to max_points
// points, largest first (ties: lower first index); each cluster's indices
// ascending. Non-finite points are in no cluster.
std::vector<std::vector<int>> euclidean_clusters(const std::vector<Vec3f>& points, double tolerance_mm,
                                                 int min_points, int max_points);

// A stable region: CVFH's smooth region growing after removing high-
// curvature points (pcl::CVFHEstimation's algorithm and parameters): points
// with curvature above cvfh_curvature_threshold are dropped, normals are
// recomputed on the rest (radius cvfh_normal_radius_mm, toward the camera;
// from a coarse support where dense, cvfh_normal_max_points), and regions
// grow between points closer than cvfh_cluster_tolerance_mm whose normals
// differ by less than cvfh_eps_angle_deg; regions of at least
// cvfh_min_region_points points are kept (regions.cpp: the regions of PCL's
// algorithm on a sorted search).
struct Region {
  std::vector<int> indices;            // of the points in the input cloud, ascending
  std::vector<Vec3f> points;
  std::vector<Vec3f> normals;          // the recomputed normals of the points
  Vec3f centroid = Vec3f::Zero();
  Vec3f mean_normal = Vec3f::UnitZ();  // unit, toward the camera
};
std::vector<Region> stable_regions(const PointSet& cloud, const GlobalSettings& s);

// --- cvfh.cpp ---
// CVFH as pcl::CVFHEstimation: one 308-bin histogram per stable region (or
// one VFH of the whole cloud if there is none), with its region's centroid
// and axis.
std::vector<Signature> cvfh_signatures(const PointSet& cloud, const GlobalSettings& s);
// The VFH (308 bins: f1, f2, f3, distance in 45 each, viewpoint in 128) of
// `points` with their `normals`, seen from `centroid` with `normal`; the
// camera at the origin. size_component false: the distance bins stay 0
// (OUR-CVFH's VFH, whose distance part its shape distribution replaces).
std::vector<float> vfh_histogram(const std::vector<Vec3f>& points, const std::vector<Vec3f>& normals,
                                 const Vec3f& centroid, const Vec3f& normal, bool normalize_bins,
                                 bool size_component = true);
// --- cvfh_pcl.cpp (PCL) ---
// pcl::CVFHEstimation itself: the reference of cvfh_signatures (tests and
// benchmarks only).
std::vector<Signature> cvfh_signatures_pcl(const PointSet& cloud, const GlobalSettings& s);
// The stable regions as pcl::CVFHEstimation grows them (pcl::NormalEstimation,
// its region growing skipping the first neighbour each search returns),
// with the region growing's search `sorted` or not (PCL's CVFH: not, so the
// first neighbour it skips is not always the seed): the reference of
// stable_regions, which equals it sorted.
std::vector<Region> stable_regions_pcl(const PointSet& cloud, const GlobalSettings& s, bool sorted);
// pcl::VFHEstimation with the given centroid and normal: the reference of
// vfh_histogram.
std::vector<float> vfh_histogram_pcl(const std::vector<Vec3f>& points, const std::vector<Vec3f>& normals,
                                     const Vec3f& centroid, const Vec3f& normal, bool normalize_bins);

// --- ourcvfh.cpp (PCL) ---
// OUR-CVFH: the stable regions and VFH above, pcl::OURCVFHEstimation's
// frames and shape distribution (run in metres: PCL hard-codes a 1 cm sigma): one
// histogram per reference frame (several per region when the axes are
// ambiguous, PCL issue 737); frames returned in mm. Guards the inputs PCL
// crashes on (issues 1449, 1491): fewer points than cvfh_min_region_points,
// non-finite normals. Signatures without a valid frame fall back to the CRH
// path (has_rf = false).
std::vector<Signature> ourcvfh_signatures(const PointSet& cloud, const GlobalSettings& s);
// pcl::OURCVFHEstimation itself, unguarded: the reference of
// ourcvfh_signatures (tests only).
std::vector<Signature> ourcvfh_signatures_pcl(const PointSet& cloud, const GlobalSettings& s);

// --- global_crh.cpp (PCL) ---
// Rotation taking the unit vector `axis` to +z (the shortest arc).
Mat3 rotation_to_z(const Vec3& axis);
// pcl::CRHEstimation (90 bins) of the cloud's normals rotated into the frame
// where `axis` is +z: the histogram of the angles of the normals projected
// onto the xy plane of that frame, as its real DFT (PCL's layout). Empty if
// the cloud has no normals.
std::vector<float> crh_spectrum(const PointSet& cloud, const Vec3f& axis);
// Roll angles theta (radians) such that the scene's normals about its axis
// look like the view's rotated by Rz(theta) (in the frames of rotation_to_z):
// the distinct peaks of the phase correlation of the two spectra (as
// pcl::CRHAlignment, sampled every degree), strongest first, each at least
// crh_peak_threshold times the strongest, at least crh_peak_distance_deg
// apart, at most crh_max_peaks.
std::vector<double> crh_roll_peaks(const std::vector<float>& scene_crh, const std::vector<float>& view_crh,
                                   const GlobalSettings& s);
// The first roll angles pcl::CRHAlignment::computeRollAngle finds for the same
// spectra, converted to our convention (radians): for tests.
std::vector<double> pcl_crh_roll_peaks(const std::vector<float>& scene_crh, const std::vector<float>& view_crh);


// --- global_method.cpp ---
// The number of ESF triples drawn for a cloud of `points` points:
// esf_samples, or `points` with esf_samples_from_points.
int esf_triples(const GlobalSettings& s, size_t points);
// R_cam_view such that R * view_axis = scene_axis: R_s^T Rz(theta) R_v with
// R_x = rotation_to_z(x).
Mat3 roll_rotation(const Vec3f& view_axis, const Vec3f& scene_axis, double theta);
// The roll that keeps the camera's up direction (-y) of the view as close as
// possible to the scene camera's (the "skip CRH" upright assumption).
double upright_roll(const Vec3f& view_axis, const Vec3f& scene_axis);

}  // namespace pb::global
