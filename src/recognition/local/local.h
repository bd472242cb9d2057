// Local pipeline settings (FPFH, SHOT, 3D Hough voting). Thesis 3.1, the
// local pipeline; defaults are the table synthetic values of Table 4.2.
#pragma once

#include "core/settings_fields.h"

namespace pb {

struct LocalSettings {
  double keypoint_voxel_mm = 15.0;      // second, coarser voxel grid (Table 4.2); the
                                        // keypoint is the cloud point nearest each voxel's centroid
  double descriptor_radius_mm = 60.0;   // FPFH / SHOT support radius (the thesis gives none;
                                        // on generated table scenes with 10 mm voxels SHOT
                                        // did clearly better at 60 than at 40, FPFH alike)
  int max_support_points = 256;         // FPFH / SHOT: a support of more points than this is
                                        // thinned evenly to this many before a histogram is
                                        // summed over it (FPFH: every SPFH and the keypoint's
                                        // sum; SHOT: the histogram, its frame still from every
                                        // point; 0 = every point, PCL's definitions). Bounds the
                                        // cost where a support radius holds thousands of points
                                        // (large objects on small voxels, noise that turns a
                                        // surface into a volume)
  bool support_from_keypoints = false;  // FPFH, SHOT and the BOARD frames take their neighbours
                                        // from the keypoints alone (the cloud sampled at
                                        // keypoint_voxel_mm), not from every point of the
                                        // cloud: for supports that hold hundreds of keypoints
                                        // (large objects: the warehouse's 545 mm radius at 50 mm
                                        // keypoints), where every point's neighbourhood costs
                                        // most of the description; false: every point, as PCL
  double lrf_radius_mm = 40.0;          // BOARD local reference frame radius (Hough voting)
  double match_threshold = 0.5;         // SHOT: max squared L2 distance between SHOT
                                        // descriptors (unit L2 norm, so in [0, 2]; PCL's
                                        // tutorial uses 0.25, too strict at 10 mm voxels)
  double fpfh_match_threshold = 250;    // FPFH: max squared L2 distance between PCL FPFH
                                        // histograms (each of the 3 sub-histograms sums to 100)
  int match_max_checks = 64;            // SHOT: approximate matching, at most this many model
                                        // descriptors measured exactly per scene keypoint (those
                                        // of the lowest bounds from 32 principal axes); 0 = exact.
                                        // Measured recall of the exact match at 64 (one image
                                        // each, Figure 4.11's statue, 0 and 2 mm of added
                                        // noise): 97.7-97.9% of the matched keypoints in the
                                        // warehouse, 99.2-99.3% on the table; 96.8% at 25 mm
                                        // (match stage 12.1 -> 4.6 s there). FPFH's search
                                        // stays exact
  int matches_per_keypoint = 3;         // k: up to k nearest model descriptors (over all
                                        // views) under the threshold kept per scene keypoint.
                                        // 3 and max_hypotheses 40 against 1 and 10 (the thesis's
                                        // pipeline; its configs pin those), the same trials, on
                                        // real YCB-Video (223 targets, icp_plane): found fpfh
                                        // 10 -> 24 (McNemar p = 0.003), shot 21 -> 30; in clutter
                                        // a keypoint's nearest model descriptor is often another
                                        // object's. Median time per object about 2x
                                        // (results/real_recognition)
  double hough_bin_mm = 50.0;           // 3D Hough bin size (Table 4.2)
  int hough_min_votes = 5;              // minimum votes for a hypothesis (thesis: 5)
  bool hough_interpolation = false;     // spread each vote over the 8 nearest bins (PCL option;
                                        // off: one vote per correspondence, as the thesis)
  int max_hypotheses = 40;              // at most this many clusters go on to refinement
                                        // (see matches_per_keypoint)
  int threads = 0;                      // OpenMP threads for FPFH / SHOT / matching (0 = OpenMP's
                                        // count: OMP_NUM_THREADS, all cores when unset); results are
                                        // identical for any value

  template <class S, class F>
  static void fields(S& s, F& f) {
    f("keypoint_voxel_mm", s.keypoint_voxel_mm, fields::length(fields::positive()));
    f("descriptor_radius_mm", s.descriptor_radius_mm, fields::length(fields::positive()));
    f("max_support_points", s.max_support_points, fields::at_least(0));
    f("support_from_keypoints", s.support_from_keypoints);
    f("lrf_radius_mm", s.lrf_radius_mm, fields::length(fields::positive()));
    f("match_threshold", s.match_threshold, fields::positive());
    f("fpfh_match_threshold", s.fpfh_match_threshold, fields::positive());
    f("match_max_checks", s.match_max_checks, fields::at_least(0));
    f("matches_per_keypoint", s.matches_per_keypoint, fields::at_least(1));
    f("hough_bin_mm", s.hough_bin_mm, fields::length(fields::positive()));
    f("hough_min_votes", s.hough_min_votes, fields::at_least(1));
    f("hough_interpolation", s.hough_interpolation);
    f("max_hypotheses", s.max_hypotheses, fields::at_least(1));
    f("threads", s.threads, fields::at_least(0));
  }
};

}  // namespace pb
