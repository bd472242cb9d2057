// RecognitionSettings <-> YAML / JSON. Each stage parser (parse_preprocess,
// parse_local, ...) lives beside its stage; this file assembles them and
// serializes every field (trial records, training cache key).
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <utility>

#include "recognition/pipeline.h"
#include "recognition/settings_internal.h"

namespace pb {

std::vector<std::string> descriptor_names() { return {"fpfh", "shot", "cvfh", "esf", "cesf", "ourcvfh", "ppf"}; }
std::vector<std::string> refinement_names() { return {"none", "icp", "icp_lm", "icp_plane", "gicp", "ndt"}; }

namespace {

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
  return s;
}

std::string read_name(const YamlNode& node, const std::string& key, const std::vector<std::string>& allowed) {
  const std::string v = node.get<std::string>(key);
  if (std::find(allowed.begin(), allowed.end(), v) == allowed.end())
    node[key].fail("unknown name '" + v + "' (allowed: " + join(allowed) + ")");
  return v;
}

void parse_views(const YamlNode& node, ViewSettings& s) {
  if (!node.defined()) return;
  node.check_keys({"views", "elevation_deg", "side_elevation_deg", "below_elevation_deg", "distance_factor",
                   "resolution", "fov_deg"});
  s.views = node.get_or<int>("views", s.views);
  if (s.views < 1) node["views"].fail("must be at least 1");
  const std::pair<const char*, double*> angles[] = {{"elevation_deg", &s.elevation_deg},
                                                     {"side_elevation_deg", &s.side_elevation_deg},
                                                     {"below_elevation_deg", &s.below_elevation_deg}};
  for (const auto& [key, v] : angles) {
    node.read(key, *v);
    if (!(std::abs(*v) <= 90)) node[key].fail("must be in [-90, 90]");
  }
  s.distance_factor = node.get_positive("distance_factor", s.distance_factor);
  s.resolution = node.get_or<int>("resolution", s.resolution);
  if (s.resolution < 8 || s.resolution > 4096) node["resolution"].fail("must be in [8, 4096]");
  s.fov_deg = node.get_positive("fov_deg", s.fov_deg);
  if (s.fov_deg >= 170) node["fov_deg"].fail("must be below 170");
}

}  // namespace

void check_descriptor_name(const std::string& name, const std::string& file, const std::string& field) {
  const auto v = descriptor_names();
  if (std::find(v.begin(), v.end(), name) == v.end())
    throw InputError(file, field, "unknown descriptor '" + name + "' (allowed: " + join(v) + ")");
}

void check_refinement_name(const std::string& name, const std::string& file, const std::string& field) {
  const auto v = refinement_names();
  if (std::find(v.begin(), v.end(), name) == v.end())
    throw InputError(file, field, "unknown refinement '" + name + "' (allowed: " + join(v) + ")");
}

RecognitionSettings parse_recognition_settings(const YamlNode& node, RecognitionSettings s) {
  if (!node.defined()) return s;
  node.check_keys({"descriptor", "refinement", "views", "preprocess", "local", "global", "ppf", "refine", "verify",
                   "seed"});
  if (node.has("descriptor")) s.descriptor = read_name(node, "descriptor", descriptor_names());
  if (node.has("refinement")) s.refinement = read_name(node, "refinement", refinement_names());
  parse_views(node["views"], s.views);
  parse_preprocess(node["preprocess"], s.preprocess);
  parse_local(node["local"], s.local);
  parse_global(node["global"], s.global);
  parse_ppf(node["ppf"], s.ppf);
  parse_refine(node["refine"], s.refine);
  parse_verify(node["verify"], s.verify);
  if (node.has("seed")) {
    const YamlNode n = node["seed"];
    const std::string text = n.as<std::string>();
    if (text.empty() || text[0] == '-') n.fail("must be a non-negative integer");
    s.seed = n.as<unsigned long long>();
  }
  return s;
}

namespace detail {
nlohmann::ordered_json settings_json(const RecognitionSettings& s) {
  nlohmann::ordered_json j;
  j["descriptor"] = s.descriptor;
  j["refinement"] = s.refinement;
  j["views"] = {{"views", s.views.views},
                {"elevation_deg", s.views.elevation_deg},
                {"side_elevation_deg", s.views.side_elevation_deg},
                {"below_elevation_deg", s.views.below_elevation_deg},
                {"distance_factor", s.views.distance_factor},
                {"resolution", s.views.resolution},
                {"fov_deg", s.views.fov_deg}};
  const auto& p = s.preprocess;
  j["preprocess"] = {{"min_range_mm", p.min_range_mm},
                     {"max_range_mm", p.max_range_mm},
                     {"voxel_mm", p.voxel_mm},
                     {"remove_plane", p.remove_plane},
                     {"plane_threshold_mm", p.plane_threshold_mm},
                     {"plane_iterations", p.plane_iterations},
                     {"min_plane_fraction", p.min_plane_fraction},
                     {"normal_radius_mm", p.normal_radius_mm}};
  const auto& l = s.local;
  j["local"] = {{"keypoint_voxel_mm", l.keypoint_voxel_mm},
                {"descriptor_radius_mm", l.descriptor_radius_mm},
                {"lrf_radius_mm", l.lrf_radius_mm},
                {"match_threshold", l.match_threshold},
                {"fpfh_match_threshold", l.fpfh_match_threshold},
                {"matches_per_keypoint", l.matches_per_keypoint},
                {"hough_bin_mm", l.hough_bin_mm},
                {"hough_min_votes", l.hough_min_votes},
                {"hough_interpolation", l.hough_interpolation},
                {"max_hypotheses", l.max_hypotheses},
                {"threads", l.threads}};
  const auto& g = s.global;
  j["global"] = {{"cluster_tolerance_mm", g.cluster_tolerance_mm},
                 {"cluster_min_points", g.cluster_min_points},
                 {"cluster_max_points", g.cluster_max_points},
                 {"cvfh_eps_angle_deg", g.cvfh_eps_angle_deg},
                 {"cvfh_curvature_threshold", g.cvfh_curvature_threshold},
                 {"cvfh_cluster_tolerance_mm", g.cvfh_cluster_tolerance_mm},
                 {"cvfh_min_region_points", g.cvfh_min_region_points},
                 {"esf_samples", g.esf_samples},
                 {"top_k", g.top_k},
                 {"crh_bins", g.crh_bins},
                 {"crh_peak_threshold", g.crh_peak_threshold},
                 {"crh_max_peaks", g.crh_max_peaks},
                 {"skip_crh", g.skip_crh},
                 {"cvfh_normal_radius_mm", g.cvfh_normal_radius_mm},
                 {"cvfh_normalize_bins", g.cvfh_normalize_bins},
                 {"crh_peak_distance_deg", g.crh_peak_distance_deg},
                 {"ourcvfh_axis_ratio", g.ourcvfh_axis_ratio},
                 {"ourcvfh_min_axis_value", g.ourcvfh_min_axis_value},
                 {"ourcvfh_refine_clusters", g.ourcvfh_refine_clusters}};
  const auto& f = s.ppf;
  j["ppf"] = {{"model_points", f.model_points},
              {"angle_step_deg", f.angle_step_deg},
              {"distance_step_fraction", f.distance_step_fraction},
              {"scene_reference_fraction", f.scene_reference_fraction},
              {"position_cluster_mm", f.position_cluster_mm},
              {"rotation_cluster_deg", f.rotation_cluster_deg},
              {"max_hypotheses", f.max_hypotheses}};
  const auto& r = s.refine;
  j["refine"] = {{"max_iterations", r.max_iterations},
                 {"max_correspondence_mm", r.max_correspondence_mm},
                 {"transformation_epsilon", r.transformation_epsilon},
                 {"rotation_epsilon_deg", r.rotation_epsilon_deg},
                 {"fitness_epsilon", r.fitness_epsilon},
                 {"reciprocal_correspondences", r.reciprocal_correspondences},
                 {"icp_sample_points", r.icp_sample_points},
                 {"ndt_resolution_mm", r.ndt_resolution_mm},
                 {"ndt_resolution_fraction", r.ndt_resolution_fraction},
                 {"ndt_step_size_mm", r.ndt_step_size_mm},
                 {"ndt_outlier_ratio", r.ndt_outlier_ratio},
                 {"ndt_min_points_per_cell", r.ndt_min_points_per_cell},
                 {"gicp_correspondence_randomness", r.gicp_correspondence_randomness},
                 {"gicp_covariances_from_normals", r.gicp_covariances_from_normals},
                 {"crop_margin_mm", r.crop_margin_mm},
                 {"normal_neighbours", r.normal_neighbours}};
  j["verify"] = {{"inlier_threshold_mm", s.verify.inlier_threshold_mm},
                 {"min_inlier_fraction", s.verify.min_inlier_fraction},
                 {"inlier_model", s.verify.inlier_model}};
  j["seed"] = s.seed;
  return j;
}

}  // namespace detail

std::string settings_to_json(const RecognitionSettings& s) { return detail::settings_json(s).dump(); }

}  // namespace pb
