// Fitting a noise model to real frames with ground truth (sensor_fit.h).
#include "simreal/sensor_fit.h"

#include <cmath>
#include <functional>
#include <map>
#include <sstream>

#include "core/error.h"
#include "core/random.h"
#include "io/bop.h"
#include "simreal/frames.h"

namespace pb {

namespace {

// What one frame contributes to every simulation: its truth (objects only)
// and its scene (objects and plane), both rendered once.
struct FitFrame {
  ImageInfo info;
  int scene_id = 0;
  RenderOutput truth, scene;
  std::vector<int> obj_ids;
};

std::vector<int> obj_ids_of(const ImageInfo& info) {
  std::vector<int> ids;
  for (const auto& g : info.gt) ids.push_back(g.obj_id);
  return ids;
}

SensorStats simulate(const std::vector<FitFrame>& frames, const SensorProfile& base, const NoiseSettings& noise,
                     const SensorFitSettings& s, const SensorStatsSettings& stats) {
  SensorStatsAccumulator acc(stats);
  for (const FitFrame& f : frames) {
    SensorProfile prof = base;
    prof.K = f.info.K;
    Rng rng(derive_seed(s.seed, {static_cast<uint64_t>(f.scene_id), static_cast<uint64_t>(f.info.im_id)}));
    DepthImage d = f.scene.depth;
    apply_noise(d, f.scene, prof, noise, rng);
    acc.add(d, f.truth, f.info.K, f.obj_ids);
  }
  return acc.finish();
}

// Missing rate over pixels nothing nearer covers, less the interior frontal
// rate (see fit_loss).
double geometric_missing(const ResidualBin& b, double r0) {
  const int64_t n = b.n - b.nearer;
  if (n <= 0) return 0;
  const double r = static_cast<double>(b.missing) / n;
  return r0 < 1 ? std::max(0.0, (r - r0) / (1 - r0)) : 0;
}

double interior_rate(const SensorStats& s) {
  const int64_t n = s.interior_frontal.n - s.interior_frontal.nearer;
  return n > 0 ? static_cast<double>(s.interior_frontal.missing) / n : 0;
}

// The disparity step from the measured depth steps: step_mm = z^2 / (fx b)
// step_px, taken where the output's 1 mm rounding no longer dominates (bins
// from 1 m whose step exceeds 1.5 mm); the median over those bins.
double disparity_step_from(const SensorStats& real, double fx, double baseline_mm, double fallback) {
  std::vector<double> px;
  for (const QuantBin& q : real.quantization) {
    const double z = 0.5 * (q.lo + q.hi);
    if (q.frames < 3 || z < 1000 || q.step_mm < 1.5) continue;
    px.push_back(q.step_mm * fx * baseline_mm / (z * z));
  }
  if (px.empty()) return fallback;
  std::sort(px.begin(), px.end());
  return px[px.size() / 2];
}

// One field the fit varies: its name, the values tried and how to set it.
struct Axis {
  std::string name;
  std::vector<double> values;
  std::function<void(NoiseSettings&, double)> set;
};

std::vector<Axis> axes_for(const std::string& model) {
  if (model == "structured_light")
    return {
        {"disparity_sigma_px", {0.1, 0.2, 0.3, 0.45, 0.6, 0.8, 1.0, 1.3},
         [](NoiseSettings& n, double v) { n.structured_light.disparity_sigma_px = v; }},
        {"smoothing_radius_px", {0, 1, 2, 3},
         [](NoiseSettings& n, double v) { n.structured_light.smoothing_radius_px = static_cast<int>(v); }},
        {"smoothing_edge_px", {0.25, 0.5, 1.0, 2.0},
         [](NoiseSettings& n, double v) { n.structured_light.smoothing_edge_px = v; }},
        {"max_incidence_deg", {65, 70, 75, 80, 85, 90},
         [](NoiseSettings& n, double v) { n.structured_light.max_incidence_deg = v; }},
        {"edge_bleed_px", {0, 0.5, 1, 1.5, 2, 3},
         [](NoiseSettings& n, double v) { n.structured_light.edge_bleed_px = v; }},
        {"edge_dropout_rate", {0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6},
         [](NoiseSettings& n, double v) { n.structured_light.edge_dropout_rate = v; }},
        {"edge_dropout_px", {1, 2, 3, 4, 6, 8},
         [](NoiseSettings& n, double v) { n.structured_light.edge_dropout_px = v; }},
    };
  // sigma = k (1.5 + 0.75 (z / 1 m)^2) mm: the literature's curve, scaled.
  return {
      {"tof_sigma_scale", {0.4, 0.55, 0.75, 1.0, 1.4, 2.0, 3.0},
       [](NoiseSettings& n, double v) { n.tof.sigma_base_mm = 1.5 * v, n.tof.sigma_per_m2_mm = 0.75 * v; }},
      {"flying_fraction", {0, 0.25, 0.5, 0.75, 1.0}, [](NoiseSettings& n, double v) { n.tof.flying_fraction = v; }},
      {"max_incidence_deg", {65, 70, 75, 80, 85, 90}, [](NoiseSettings& n, double v) { n.tof.max_incidence_deg = v; }},
      {"edge_filter_span_mm", {50, 100, 150, 200}, [](NoiseSettings& n, double v) { n.tof.edge_filter_span_mm = v; }},
  };
}

}  // namespace

FitLoss fit_loss(const SensorStats& real, const SensorStats& sim, int64_t min_pixels) {
  FitLoss L;
  auto mean_over = [&](const std::vector<ResidualBin>& a, const std::vector<ResidualBin>& b, auto term,
                       auto use) {
    double sum = 0;
    int n = 0;
    for (size_t i = 0; i < a.size() && i < b.size(); ++i) {
      if (a[i].n < min_pixels || b[i].n < min_pixels || !use(a[i])) continue;
      sum += term(a[i], b[i]);
      ++n;
    }
    return n ? sum / n : 0.0;
  };
  auto all = [](const ResidualBin&) { return true; };
  L.noise = mean_over(real.by_depth, sim.by_depth,
                      [](const ResidualBin& a, const ResidualBin& b) {
                        if (a.spread_mm <= 0 || b.spread_mm <= 0) return 4.0;  // no inliers on one side
                        const double l = std::log(b.spread_mm / a.spread_mm);
                        return l * l;
                      },
                      [](const ResidualBin& a) { return a.inliers >= 100; });
  // The real rates less what no model here produces; the simulated as they are.
  const double r0 = interior_rate(real);
  auto miss = [&](const ResidualBin& a, const ResidualBin& b) {
    const double d = (geometric_missing(b, 0) - geometric_missing(a, r0)) / 0.1;
    return d * d;
  };
  L.incidence = mean_over(real.by_incidence, sim.by_incidence, miss, all);
  L.edge = mean_over(real.by_edge_px, sim.by_edge_px, miss, [](const ResidualBin& a) { return a.lo <= 5; });
  double sum = 0;
  int n = 0;
  for (size_t i = 0; i < real.silhouette.size() && i < sim.silhouette.size(); ++i) {
    const SilhouetteBin &a = real.silhouette[i], &b = sim.silhouette[i];
    if (a.d < -2 || a.d > 3 || a.n < min_pixels || b.n < min_pixels) continue;
    const double d = (b.object_rate() - a.object_rate()) / 0.1;
    sum += d * d;
    ++n;
  }
  L.silhouette = n ? sum / n : 0;
  return L;
}

namespace {

// The frames the fit simulates, one per ground-truth frame: its twin's
// renders (the truth and the scene), the real frame's statistics added to
// `real`, its support plane listed in r.planes; [depth_lo, depth_hi] takes
// in the real frames' depths.
std::vector<FitFrame> twin_frames(const BopDataset& ds, const SensorFitSettings& s, SensorStatsAccumulator& real,
                                  SensorFitResult& r, double& depth_lo, double& depth_hi) {
  std::vector<GtFrame> gt_frames = list_gt_frames(ds, s.split, s.max_images, s.stride);
  RendererPool pool;
  ModelMeshes meshes(ds);
  std::vector<FitFrame> frames;
  for (GtFrame& g : gt_frames) {
    load_gt_depth(ds, s.split, g);
    const int sid = g.scene_id, iid = g.info.im_id;
    for (float z : g.depth.z)
      if (z > 0) depth_lo = std::min<double>(depth_lo, z), depth_hi = std::max<double>(depth_hi, z);
    FitFrame f;
    f.info = g.info;
    f.scene_id = sid;
    f.obj_ids = obj_ids_of(g.info);
    TwinRender tr = render_twin(pool, meshes, g, derive_seed(s.seed, {7, static_cast<uint64_t>(sid),
                                                                        static_cast<uint64_t>(iid)}));
    f.truth = std::move(tr.truth);
    f.scene = std::move(tr.scene);
    const SupportPlane& plane = tr.plane;
    real.add(g.depth, f.truth, g.info.K, f.obj_ids);
    g.depth = DepthImage();  // the renders are what the fit keeps
    r.planes.push_back({{"scene_id", sid}, {"im_id", iid}, {"found", plane.found}, {"inliers", plane.inliers},
                        {"candidates", plane.candidates}});
    if (frames.empty()) r.K = g.info.K;
    frames.push_back(std::move(f));
  }
  return frames;
}

// Coordinate descent over the axes' values from their middle values: each
// axis in turn takes the value of the least loss(x), the others held;
// passes until none changes (at most 3). The values found, axis by axis.
std::vector<double> coordinate_descent(const std::vector<Axis>& axes,
                                       const std::function<double(const std::vector<double>&)>& loss) {
  std::vector<double> at(axes.size());
  for (size_t k = 0; k < axes.size(); ++k) at[k] = axes[k].values[axes[k].values.size() / 2];
  double best = loss(at);
  for (int pass = 0; pass < 3; ++pass) {
    bool changed = false;
    for (size_t k = 0; k < axes.size(); ++k)
      for (double v : axes[k].values) {
        std::vector<double> x = at;
        x[k] = v;
        const double l = loss(x);
        if (l < best - 1e-12) best = l, at = x, changed = true;
      }
    if (!changed) break;
  }
  return at;
}

}  // namespace

SensorFitResult fit_sensor(const std::string& dataset, const SensorFitSettings& s) {
  const std::string& model = s.base.noise.model;
  if (model != "structured_light" && model != "tof")
    throw InputError(dataset, "--base", "the base profile's noise model is '" + model +
                                            "'; sensor-fit fits structured_light or tof");
  const BopDataset ds(dataset);
  SensorFitResult r;
  r.dataset = dataset;
  r.planes = nlohmann::ordered_json::array();
  // The final statistics also measure the normals (too slow for every candidate).
  SensorStatsSettings with_normals = s.stats;
  if (with_normals.normal_window_px == 0) with_normals.normal_window_px = 5;
  SensorStatsAccumulator real(with_normals);
  double depth_lo = 1e300, depth_hi = 0;
  const std::vector<FitFrame> frames = twin_frames(ds, s, real, r, depth_lo, depth_hi);
  r.images = static_cast<int>(frames.size());
  // The sensor measured what the frames show: the base's range widens to
  // take it in (a close-range mode, say), else the simulation drops it.
  SensorProfile base = s.base;
  base.min_range_mm = std::min(base.min_range_mm, std::floor(0.95 * depth_lo));
  base.max_range_mm = std::min(65535.0 * base.depth_scale, std::max(base.max_range_mm, std::ceil(1.05 * depth_hi)));
  r.real = real.finish();
  NoiseSettings start = s.base.noise;
  if (model == "structured_light")
    start.structured_light.disparity_step_px = disparity_step_from(
        r.real, r.K.fx, start.structured_light.baseline_mm, start.structured_light.disparity_step_px);
  r.base = simulate(frames, base, base.noise, s, with_normals);
  r.base_loss = fit_loss(r.real, r.base);
  // Each candidate simulated once (the descent asks again for values it met).
  const std::vector<Axis> axes = axes_for(model);
  std::map<std::vector<double>, double> seen;
  auto evaluate = [&](const std::vector<double>& x) {
    if (auto it = seen.find(x); it != seen.end()) return it->second;
    FitCandidate c;
    c.noise = start;
    for (size_t k = 0; k < axes.size(); ++k) {
      axes[k].set(c.noise, x[k]);
      c.params[axes[k].name] = x[k];
    }
    c.loss = fit_loss(r.real, simulate(frames, base, c.noise, s, s.stats));
    r.candidates.push_back(c);
    return seen[x] = c.loss.total();
  };
  const std::vector<double> at = coordinate_descent(axes, evaluate);
  NoiseSettings cur = start;
  for (size_t k = 0; k < axes.size(); ++k) axes[k].set(cur, at[k]);
  r.profile = base;
  r.profile.name = s.name;
  r.profile.K = r.K;
  r.profile.noise = cur;
  if (model == "structured_light") r.profile.noise.structured_light.reference_fx = r.K.fx;
  r.fitted = simulate(frames, base, r.profile.noise, s, with_normals);
  return r;
}

std::string profile_yaml(const SensorProfile& p, const std::string& comment) {
  std::ostringstream o;
  o.precision(10);
  std::istringstream lines(comment);
  for (std::string l; std::getline(lines, l);) o << "# " << l << "\n";
  o << "name: " << p.name << "\n"
    << "width: " << p.K.width << "\nheight: " << p.K.height << "\n"
    << "fx: " << p.K.fx << "\nfy: " << p.K.fy << "\ncx: " << p.K.cx << "\ncy: " << p.K.cy << "\n"
    << "depth_scale: " << p.depth_scale << "\n"
    << "min_range_mm: " << p.min_range_mm << "\nmax_range_mm: " << p.max_range_mm << "\n"
    << "noise:\n";
  const nlohmann::ordered_json noise = noise_json(p.noise);
  for (const auto& [k, v] : noise.items()) o << "  " << k << ": " << v.dump() << "\n";
  return o.str();
}

namespace {

nlohmann::ordered_json loss_json(const FitLoss& l) {
  return {{"total", l.total()}, {"noise", l.noise}, {"incidence", l.incidence}, {"edge", l.edge},
          {"silhouette", l.silhouette}};
}

}  // namespace

nlohmann::ordered_json to_json(const SensorFitResult& r) {
  nlohmann::ordered_json j;
  j["dataset"] = r.dataset;
  j["images"] = r.images;
  j["intrinsics"] = {{"width", r.K.width}, {"height", r.K.height}, {"fx", r.K.fx},
                     {"fy", r.K.fy},       {"cx", r.K.cx},         {"cy", r.K.cy}};
  j["profile"] = {{"name", r.profile.name}, {"noise", noise_json(r.profile.noise)}};
  j["loss"] = {{"base", loss_json(r.base_loss)}, {"fitted", loss_json(fit_loss(r.real, r.fitted))}};
  j["real"] = to_json(r.real);
  j["simulated_base"] = to_json(r.base);
  j["simulated_fitted"] = to_json(r.fitted);
  nlohmann::ordered_json c = nlohmann::ordered_json::array();
  for (const auto& x : r.candidates) c.push_back({{"params", x.params}, {"loss", loss_json(x.loss)}});
  j["candidates"] = c;
  j["planes"] = r.planes;
  return j;
}

}  // namespace pb
