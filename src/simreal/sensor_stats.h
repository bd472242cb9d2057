// A depth frame against the depth rendered from its ground truth, pixel by
// pixel: what `posebench sensor-fit` measures on real frames and, with the
// same code, on simulated ones (the fit and the twin scenes).
//
// The truth is a render of the annotated objects alone at their GT poses
// (labels = index of the GT instance, normals on). Every statistic is over
// object pixels (a GT object drawn there) unless it says otherwise:
// - residual r = measured - true depth; a pixel is an inlier when |r| <=
//   outlier_mm + outlier_rel * z, "nearer" when something stands in front
//   (an unannotated object, a hand), "farther" when the sensor saw past the
//   surface (a shrunk silhouette, a shiny surface, a GT error), "missing"
//   when the sensor gave no depth;
// - bias (median inlier residual) and spread (1.4826 x its median absolute
//   deviation), by true depth, by incidence angle (between the viewing ray
//   and the surface normal) and by distance to the object's silhouette;
// - the silhouette: for each signed distance to the rendered outline (inside
//   <= 0, outside > 0, up to silhouette_px) whether the measured depth is the
//   object's (within the inlier band of the nearest object pixel's depth),
//   farther, nearer or missing: outside pixels measured as object mean a
//   grown silhouette, inside pixels measured farther or missing a shrunk
//   one, values between object and background mixed pixels;
// - quantization: per frame and depth bin, the median gap between
//   consecutive distinct measured depths (every valid pixel, not only object
//   pixels), then the median over frames.
#pragma once

#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <vector>

#include "core/types.h"
#include "render/renderer.h"

namespace pb {

struct SensorStatsSettings {
  double depth_bin_mm = 250;      // width of a true-depth bin
  double max_depth_mm = 4000;     // deeper object pixels are not binned by depth
  double incidence_bin_deg = 10;  // width of an incidence-angle bin
  double outlier_mm = 15;         // inlier band: |r| <= outlier_mm + outlier_rel * z
  double outlier_rel = 0.01;
  int silhouette_px = 5;          // signed silhouette distances -silhouette_px..silhouette_px
  int edge_bins_px = 12;          // inside distances 0..edge_bins_px-1, the last bin open
  int min_quant_values = 5;       // a frame's bin needs this many distinct depths for a step
  // Normals: the plane through the measured points of a pixel's window
  // (2w+1)^2 on the same object, against the rendered normal, at every
  // normal_stride-th pixel of every normal_stride-th row. 0 = not measured.
  int normal_window_px = 0;
  int normal_stride = 3;
};

// The angle (deg) between the normal of the measured points and the true
// normal, over the object pixels of one depth bin.
struct NormalBin {
  double lo = 0, hi = 0;  // true depth (mm)
  int64_t n = 0;
  double median_deg = 0, p90_deg = 0;
};

// Counts and residual statistics of the object pixels in one bin.
struct ResidualBin {
  double lo = 0, hi = 0;  // the bin (mm, degrees or px; hi = lo for an integer distance)
  int64_t n = 0;          // object pixels
  int64_t missing = 0, nearer = 0, farther = 0, inliers = 0;
  double bias_mm = 0;     // median inlier residual (0 without inliers)
  double spread_mm = 0;   // 1.4826 x median absolute deviation of the inlier residuals, each
                          // centred on its instance's median (an offset of the GT pose is no noise)
  double missing_rate() const { return n ? static_cast<double>(missing) / n : 0; }
};

// What the measured depth is at a signed distance from the rendered outline.
struct SilhouetteBin {
  int d = 0;  // px; <= 0 inside the object (0 = its outermost pixels), > 0 outside
  int64_t n = 0, object = 0, farther = 0, nearer = 0, missing = 0;
  double object_rate() const { return n ? static_cast<double>(object) / n : 0; }
};

struct QuantBin {
  double lo = 0, hi = 0;  // depth bin (mm)
  int frames = 0;         // frames with enough distinct depths in the bin
  double step_mm = 0;     // median over frames of the median gap between distinct depths
};

struct SensorStats {
  SensorStatsSettings settings;
  int images = 0;
  ResidualBin all;
  std::vector<ResidualBin> by_depth, by_incidence, by_edge_px;
  std::vector<SilhouetteBin> silhouette;  // d = -silhouette_px .. silhouette_px
  std::vector<QuantBin> quantization;
  std::map<int, ResidualBin> by_object;   // obj_id -> its pixels
  // Missing data the geometry does not explain: object pixels at incidence
  // below 45 deg and at least 8 px inside the outline (dark or shiny
  // surfaces, multipath, interference; no noise model here drops them).
  ResidualBin interior_frontal;
  std::vector<NormalBin> normal_error;  // by depth; empty unless normal_window_px > 0
};

class SensorStatsAccumulator {
 public:
  explicit SensorStatsAccumulator(SensorStatsSettings s = {});
  // measured: the frame (mm, 0 = no depth); truth: the GT objects rendered
  // with normals, labels[p] = index into obj_ids; same size as measured.
  void add(const DepthImage& measured, const RenderOutput& truth, const Intrinsics& K,
           const std::vector<int>& obj_ids);
  SensorStats finish() const;

 private:
  struct Acc {
    ResidualBin bin;
    std::vector<float> r, rc;  // inlier residuals, and centred on their instance's median
  };
  void count(Acc& a, double r, double centre, bool missing, double z) const;
  SensorStatsSettings s_;
  int images_ = 0;
  Acc all_, interior_;
  std::vector<Acc> depth_, incidence_, edge_;
  std::map<int, Acc> object_;
  std::vector<SilhouetteBin> sil_;
  std::vector<std::vector<double>> quant_steps_;  // per depth bin, one step per frame
  std::vector<std::vector<float>> normal_deg_;    // per depth bin
  // Each instance's median inlier residual: its offset along the ray.
  std::vector<double> instance_centres(const DepthImage& measured, const RenderOutput& truth, size_t instances) const;
  void add_normals(const DepthImage& measured, const RenderOutput& truth, const Intrinsics& K);
  // Quantization: the step between distinct measured depths per depth bin
  // of this frame (their median gap).
  void add_quantization(const DepthImage& measured);
};

// Object pixels' distance (4-connected steps) to the nearest pixel of
// another label, capped at `cap`; -1 where no object is drawn. Exposed for
// tests.
std::vector<int> inside_edge_distance(const std::vector<int32_t>& labels, int width, int height, int cap);
// Non-object pixels' distance (4-connected steps, 1 = next to an object) to
// the nearest object pixel, up to `cap` (-1 farther), and that pixel's index.
void outside_distance(const std::vector<int32_t>& labels, int width, int height, int cap, std::vector<int>& dist,
                      std::vector<int>& nearest);

nlohmann::ordered_json to_json(const SensorStats& s);

}  // namespace pb
