// Refinement (registration): the `refine` settings, one struct per method
// family, and refine_pose, which registers a model view (source) to the
// scene (target, thesis) with a Refiner (refiner.h): ICP, ICP-LM, ICP
// point-to-plane, GICP, 3D-NDT.
#pragma once

#include <string>
#include <vector>

#include "core/types.h"
#include "core/settings_fields.h"
#include "recognition/cloud.h"

namespace pb {

// Units: every *_mm field is in millimetres. PCL registers in metres (float),
// in a frame centred on the cropped scene (refine_pose.cpp), so the epsilons
// marked "m" are in metres as PCL compares them.

// What every registration method reads: the iteration cap, the
// correspondence bound and the stopping rules (the top of the `refine`
// section).
struct RegistrationSettings {
  int max_iterations = 40;                 // thesis: at most 40 iterations
  double max_correspondence_mm = 20.0;     // pairs farther apart are rejected
  double transformation_epsilon = 1e-8;    // stop on small change of transform: squared translation
                                           // step below this (m^2; 1e-8 = (0.1 mm)^2), together with
                                           // a rotation step below rotation_epsilon_deg
  double rotation_epsilon_deg = 0.05;      // rotation part of the transform-change stopping rule
  double fitness_epsilon = 1e-6;           // stop on small change of mean squared error: relative
                                           // change between iterations (ICP, ICP-LM, ICP-plane)
  bool reciprocal_correspondences = true;  // ICP, ICP-LM, ICP-plane: keep only mutual nearest
                                           // neighbours (PCL's reciprocal correspondences); makes
                                           // them robust to surface seen in one cloud only

  template <class S, class F>
  static void fields(S& s, F& f) {
    f("max_iterations", s.max_iterations, fields::at_least(1));
    f("max_correspondence_mm", s.max_correspondence_mm, fields::length(fields::positive()));
    f("transformation_epsilon", s.transformation_epsilon, fields::nonnegative());
    f("rotation_epsilon_deg", s.rotation_epsilon_deg, fields::nonnegative());
    f("fitness_epsilon", s.fitness_epsilon, fields::nonnegative());
    f("reciprocal_correspondences", s.reciprocal_correspondences);
  }
};

// The project's ICP (icp, icp_plane; sample_points also icp_pcl): `refine.icp`.
struct IcpSettings {
  int sample_points = 0;     // seeded random subset of this many source points (0 = all)
  int coarse_points = 1000;  // a source of more points is registered coarse to fine: first a
                             // seeded random subset of this many, then all of them from there
                             // (0 = one stage on all, as PCL)
  int fine_iterations = 10;  // ... of max_iterations, at least this many are left to the fine
                             // stage (the coarse one stops earlier on a stopping rule and
                             // leaves it the rest)

  template <class S, class F>
  static void fields(S& s, F& f) {
    f("sample_points", s.sample_points, fields::at_least(0));
    f("coarse_points", s.coarse_points, fields::at_least(0));
    f("fine_iterations", s.fine_iterations, fields::at_least(1));
  }
};

// Generalized ICP (gicp): `refine.gicp`.
struct GicpSettings {
  double correspondence_randomness = 20;  // neighbours for covariances (when not from normals)
  bool covariances_from_normals = true;   // plane covariances built from the clouds' normals
                                          // (thesis: "covariances from normals"); false = PCL's
                                          // own k-neighbour covariances

  template <class S, class F>
  static void fields(S& s, F& f) {
    f("correspondence_randomness", s.correspondence_randomness, fields::at_least(3));
    f("covariances_from_normals", s.covariances_from_normals);
  }
};

// 3D-NDT (ndt): `refine.ndt`.
struct NdtSettings {
  double resolution_mm = 30.0;        // grid cell, at least this (a planar cell needs about 6 scene
                                      // points: >= 2.5 x the scene voxel; 30 mm for the table's
                                      // 10 mm voxel)
  double resolution_fraction = 0.15;  // grid sized to the object: cell = this fraction of the
                                      // model cloud's bounding box diagonal, but at least
                                      // resolution_mm (0: resolution_mm alone)
  double step_size_mm = 80.0;         // max More-Thuente step (PCL's 6-vector of metres and
                                      // radians: 80 mm also allows 4.6 degrees per step)
  double outlier_ratio = 0.55;        // outlier ratio of the Gaussian mixture (PCL default)
  int min_points_per_cell = 6;        // cells with fewer scene points are ignored (PCL default 6,
                                      // at least 3)

  template <class S, class F>
  static void fields(S& s, F& f) {
    f("resolution_mm", s.resolution_mm, fields::length(fields::positive()));
    f("resolution_fraction", s.resolution_fraction, fields::nonnegative());
    f("step_size_mm", s.step_size_mm, fields::length(fields::positive()));
    f("outlier_ratio", s.outlier_ratio, fields::positive());
    f("min_points_per_cell", s.min_points_per_cell, fields::at_least(3));
  }
  void validate(const YamlNode& node) const {
    if (outlier_ratio >= 1) node["outlier_ratio"].fail("must be below 1");
  }
};

// The `refine` section: the settings every method reads, the pipeline's own
// (crop, normals, which hypotheses), and one subsection per method family
// with what that family alone reads. The registry (registry.h) builds a
// method with the common settings and its subsection.
struct RefineSettings : RegistrationSettings {
  double crop_margin_mm = -1;              // scene crop: points within model radius + this of the
                                           // initial model centre are registered (< 0: use
                                           // max_correspondence_mm, which is relative by default; a
                                           // fraction "0.05d" is allowed)
  int normal_neighbours = 10;              // k for PCA normals when a cloud has none (icp_plane, gicp)
  int max_hypotheses = 0;                  // refine only this many hypotheses: those verification
                                           // would rank first (verify.score, ties as there) at their
                                           // initial pose, or after screening (screen_points); the
                                           // others are dropped. 0 = refine every hypothesis (thesis)
  int screen_points = 0;                   // with max_hypotheses: every hypothesis is first
                                           // registered (this method, max_iterations) on a seeded
                                           // random subset of this many of its model points and
                                           // ranked at that pose; the kept ones are refined on all
                                           // points from there. 0 = rank at the initial pose
  IcpSettings icp;                         // icp, icp_plane (icp_pcl: sample_points)
  GicpSettings gicp;                       // gicp
  NdtSettings ndt;                         // ndt

  template <class S, class F>
  static void fields(S& s, F& f) {
    RegistrationSettings::fields(s, f);
    f("crop_margin_mm", s.crop_margin_mm, fields::length({}));  // a length ("0.05d"); < 0: the sentinel
    f("normal_neighbours", s.normal_neighbours, fields::at_least(3));
    f("max_hypotheses", s.max_hypotheses, fields::at_least(0));
    f("screen_points", s.screen_points, fields::at_least(0));
    f.section("icp", s.icp);
    f.section("gicp", s.gicp);
    f.section("ndt", s.ndt);
  }
};

struct RefineResult {
  Pose T_cam_model;        // refined pose
  bool converged = false;
  int iterations = 0;
};

class KdTree3;
class Refiner;

// Refines `init` (T_cam_model) by aligning `model` (points in the model
// frame, with normals) to `scene` (camera frame, with normals) with
// `refiner` (refiner.h; null: "none", the initial pose stands). Random
// choices draw from `seed`. scene_tree (optional): a KdTree3 over
// scene.points (verification's, PointIndex::tree()); the crop's tree is
// then cut from it (KdTree3::restricted) instead of built, with the same
// answers. One caller refining many hypotheses in one scene passes it.
RefineResult refine_pose(const Refiner* refiner, const PointSet& model, const PointSet& scene, const Pose& init,
                         const RefineSettings& s, uint64_t seed, const KdTree3* scene_tree = nullptr);


// How well `model` (model frame) at T_cam_model fits `scene` (camera frame):
// the mean squared distance (mm^2) of the model points to their nearest
// scene point, over the points whose nearest lies within max_distance_mm
// (PCL's Registration::getFitnessScore with a bound); max_distance_mm^2 when
// none does. Not part of refine_pose (the pipeline ranks by verification and
// never reads it: one nearest-neighbour search per model point saved).
double registration_fitness(const PointSet& model, const PointSet& scene, const Pose& T_cam_model,
                            double max_distance_mm);

}  // namespace pb
