// Stable rest poses of a rigid object on a horizontal plane, from its mesh.
//
// How: the 3D convex hull of the vertices is computed (quickhull); hull
// triangles lying in one plane are merged into facets. A facet is a rest pose
// when the centre of mass (of the solid, uniform density) projects into the
// facet's polygon with a margin. Its probability is the solid angle the facet
// subtends at the centre of mass (the quasi-static estimate of how often a
// dropped object lands on that facet), normalized over the stable facets.
#pragma once

#include <vector>

#include "core/random.h"
#include "core/types.h"

namespace pb {

struct RestPose {
  Vec3 normal;           // outward unit normal of the contact facet, model frame
  double probability = 0;
  double margin_mm = 0;  // distance from the projected centre of mass to the facet's border
  // Rotation taking the model frame to a frame whose -z is `normal` (the
  // object standing on the facet); yaw about +z is free.
  Mat3 R_rest;
};

struct RestPoses {
  std::vector<RestPose> poses;  // sorted by probability, largest first
  int upright = -1;             // index of the pose closest to "standing" (normal ~ -z), -1 if none
  Vec3 centre_of_mass = Vec3::Zero();
};

// Convex hull of points: triangles (counter-clockwise seen from outside) as
// indices into `points`. Degenerate (flat or collinear) inputs give an empty
// result.
std::vector<Eigen::Vector3i> convex_hull_3d(const std::vector<Vec3>& points);

// Centre of mass of the solid bounded by the mesh (signed volume integration);
// falls back to the centroid of the convex hull's solid for open or flat meshes.
Vec3 centre_of_mass(const Mesh& mesh);

// Rest poses of the mesh. The margin required for a facet to count as stable
// is `min_margin_fraction` times the bounding box diagonal (at least 0.05 mm):
// small, so that round objects rest on the narrow strips of their side.
RestPoses compute_rest_poses(const Mesh& mesh, double min_margin_fraction = 0.002);

// Draws a rest pose: the upright one with probability `upright_probability`
// (if it exists), otherwise one by the facets' probabilities.
int sample_rest_pose(const RestPoses& rp, double upright_probability, Rng& rng);

// 2D convex hull (Andrew's monotone chain), counter-clockwise, no repeated
// first point; collinear points dropped.
std::vector<Eigen::Vector2d> convex_hull_2d(std::vector<Eigen::Vector2d> pts);

// Whether two convex polygons (counter-clockwise) come closer than `gap`
// (separating axis test on the polygons grown by gap / 2 along each axis).
bool convex_polygons_overlap(const std::vector<Eigen::Vector2d>& a,
                             const std::vector<Eigen::Vector2d>& b, double gap);

}  // namespace pb
