// The `global:` YAML section (GlobalSettings, global.h).
#include <string>

#include "recognition/global/global.h"

namespace pb {

void parse_global(const YamlNode& node, GlobalSettings& s) {
  if (!node.defined()) return;
  node.check_keys({"cluster_tolerance_mm", "cluster_min_points", "cluster_max_points", "cvfh_eps_angle_deg",
                   "cvfh_curvature_threshold", "cvfh_cluster_tolerance_mm", "cvfh_min_region_points",
                   "esf_samples", "top_k", "crh_bins", "crh_peak_threshold", "crh_max_peaks", "skip_crh",
                   "cvfh_normal_radius_mm", "cvfh_normalize_bins", "crh_peak_distance_deg",
                   "ourcvfh_axis_ratio", "ourcvfh_min_axis_value", "ourcvfh_refine_clusters"});
  auto int_at_least = [&](const std::string& key, int& v, int lo) {
    v = node.get_or<int>(key, v);
    if (v < lo) node[key].fail("must be at least " + std::to_string(lo) + ", got " + std::to_string(v));
  };
  s.cluster_tolerance_mm = node.get_positive("cluster_tolerance_mm", s.cluster_tolerance_mm);
  int_at_least("cluster_min_points", s.cluster_min_points, 1);
  int_at_least("cluster_max_points", s.cluster_max_points, 1);
  if (s.cluster_max_points < s.cluster_min_points)
    node["cluster_max_points"].fail("must be at least cluster_min_points (" + std::to_string(s.cluster_min_points) +
                                    ")");
  s.cvfh_eps_angle_deg = node.get_positive("cvfh_eps_angle_deg", s.cvfh_eps_angle_deg);
  if (s.cvfh_eps_angle_deg > 180) node["cvfh_eps_angle_deg"].fail("must be at most 180 degrees");
  s.cvfh_curvature_threshold = node.get_positive("cvfh_curvature_threshold", s.cvfh_curvature_threshold);
  s.cvfh_cluster_tolerance_mm = node.get_positive("cvfh_cluster_tolerance_mm", s.cvfh_cluster_tolerance_mm);
  int_at_least("cvfh_min_region_points", s.cvfh_min_region_points, 3);
  int_at_least("esf_samples", s.esf_samples, 1);
  int_at_least("top_k", s.top_k, 1);
  s.crh_bins = node.get_or<int>("crh_bins", s.crh_bins);
  if (s.crh_bins != 90) node["crh_bins"].fail("must be 90 (pcl::CRHEstimation has 90 bins), got " + std::to_string(s.crh_bins));
  s.crh_peak_threshold = node.get_nonnegative("crh_peak_threshold", s.crh_peak_threshold);
  if (s.crh_peak_threshold > 1) node["crh_peak_threshold"].fail("must be in [0, 1]");
  int_at_least("crh_max_peaks", s.crh_max_peaks, 1);
  node.read("skip_crh", s.skip_crh);
  s.cvfh_normal_radius_mm = node.get_positive("cvfh_normal_radius_mm", s.cvfh_normal_radius_mm);
  node.read("cvfh_normalize_bins", s.cvfh_normalize_bins);
  s.crh_peak_distance_deg = node.get_nonnegative("crh_peak_distance_deg", s.crh_peak_distance_deg);
  if (s.crh_peak_distance_deg > 180) node["crh_peak_distance_deg"].fail("must be at most 180 degrees");
  s.ourcvfh_axis_ratio = node.get_positive("ourcvfh_axis_ratio", s.ourcvfh_axis_ratio);
  if (s.ourcvfh_axis_ratio > 1) node["ourcvfh_axis_ratio"].fail("must be in (0, 1]");
  s.ourcvfh_min_axis_value = node.get_positive("ourcvfh_min_axis_value", s.ourcvfh_min_axis_value);
  if (s.ourcvfh_min_axis_value > 1) node["ourcvfh_min_axis_value"].fail("must be in (0, 1]");
  s.ourcvfh_refine_clusters = node.get_positive("ourcvfh_refine_clusters", s.ourcvfh_refine_clusters);
}

}  // namespace pb
