// Measured depth against the rendered ground truth (sensor_stats.h).
#include "simreal/sensor_stats.h"

#include <algorithm>
#include <cmath>
#include <Eigen/Eigenvalues>
#include <deque>
#include <functional>

namespace pb {

namespace {

double median(std::vector<float>& v) {
  if (v.empty()) return 0;
  const size_t m = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + m, v.end());
  double x = v[m];
  if (v.size() % 2 == 0) x = 0.5 * (x + *std::max_element(v.begin(), v.begin() + m));
  return x;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

// Fills bias from the inlier residuals and spread from the same residuals
// centred on their instance's median (so an instance's GT offset along the
// ray does not count as noise).
ResidualBin finish_bin(ResidualBin b, std::vector<float> r, std::vector<float> rc) {
  if (r.empty()) return b;
  b.bias_mm = median(r);
  const double m = median(rc);
  for (float& x : rc) x = static_cast<float>(std::abs(x - m));
  b.spread_mm = 1.4826 * median(rc);
  return b;
}

// Multi-source breadth-first distance over 4-neighbours: `dist` holds 0 at
// the sources and -1 elsewhere; `may_enter(p)` limits the region; the
// nearest source's index propagates in `src`.
void bfs(std::vector<int>& dist, std::vector<int>& src, int W, int H, int cap,
         const std::function<bool(size_t)>& may_enter) {
  std::deque<size_t> q;
  for (size_t p = 0; p < dist.size(); ++p)
    if (dist[p] == 0) q.push_back(p);
  while (!q.empty()) {
    const size_t p = q.front();
    q.pop_front();
    if (dist[p] >= cap) continue;
    const int u = static_cast<int>(p % W), v = static_cast<int>(p / W);
    const int nu[4] = {u - 1, u + 1, u, u}, nv[4] = {v, v, v - 1, v + 1};
    for (int k = 0; k < 4; ++k) {
      if (nu[k] < 0 || nv[k] < 0 || nu[k] >= W || nv[k] >= H) continue;
      const size_t n = static_cast<size_t>(nv[k]) * W + nu[k];
      if (dist[n] != -1 || !may_enter(n)) continue;
      dist[n] = dist[p] + 1;
      src[n] = src[p];
      q.push_back(n);
    }
  }
}

}  // namespace

std::vector<int> inside_edge_distance(const std::vector<int32_t>& labels, int W, int H, int cap) {
  std::vector<int> dist(labels.size(), -1), src(labels.size(), -1);
  for (int v = 0; v < H; ++v)
    for (int u = 0; u < W; ++u) {
      const size_t p = static_cast<size_t>(v) * W + u;
      if (labels[p] < 0) continue;
      const bool edge = (u > 0 && labels[p - 1] != labels[p]) || (u + 1 < W && labels[p + 1] != labels[p]) ||
                        (v > 0 && labels[p - W] != labels[p]) || (v + 1 < H && labels[p + W] != labels[p]);
      if (edge) dist[p] = 0, src[p] = static_cast<int>(p);
    }
  bfs(dist, src, W, H, cap, [&](size_t n) { return labels[n] >= 0; });
  // Object pixels the search did not reach lie farther than cap.
  for (size_t p = 0; p < labels.size(); ++p)
    if (labels[p] >= 0 && dist[p] < 0) dist[p] = cap;
  return dist;
}

void outside_distance(const std::vector<int32_t>& labels, int W, int H, int cap, std::vector<int>& dist,
                      std::vector<int>& nearest) {
  dist.assign(labels.size(), -1);
  nearest.assign(labels.size(), -1);
  for (size_t p = 0; p < labels.size(); ++p)
    if (labels[p] >= 0) dist[p] = 0, nearest[p] = static_cast<int>(p);
  bfs(dist, nearest, W, H, cap, [&](size_t n) { return labels[n] < 0; });
  for (size_t p = 0; p < labels.size(); ++p)
    if (labels[p] >= 0) dist[p] = -1, nearest[p] = -1;  // only outside pixels carry a distance
}

SensorStatsAccumulator::SensorStatsAccumulator(SensorStatsSettings s) : s_(s) {
  const int nd = static_cast<int>(std::ceil(s_.max_depth_mm / s_.depth_bin_mm));
  depth_.resize(nd);
  quant_steps_.resize(nd);
  normal_deg_.resize(nd);
  for (int i = 0; i < nd; ++i) depth_[i].bin.lo = i * s_.depth_bin_mm, depth_[i].bin.hi = (i + 1) * s_.depth_bin_mm;
  const int ni = static_cast<int>(std::ceil(90.0 / s_.incidence_bin_deg));
  incidence_.resize(ni);
  for (int i = 0; i < ni; ++i)
    incidence_[i].bin.lo = i * s_.incidence_bin_deg, incidence_[i].bin.hi = std::min(90.0, (i + 1) * s_.incidence_bin_deg);
  edge_.resize(s_.edge_bins_px);
  for (int i = 0; i < s_.edge_bins_px; ++i) edge_[i].bin.lo = edge_[i].bin.hi = i;
  edge_.back().bin.hi = 1e9;
  for (int d = -s_.silhouette_px; d <= s_.silhouette_px; ++d) sil_.push_back(SilhouetteBin{d});
}

void SensorStatsAccumulator::count(Acc& a, double r, double centre, bool missing, double z) const {
  ++a.bin.n;
  if (missing) {
    ++a.bin.missing;
    return;
  }
  const double band = s_.outlier_mm + s_.outlier_rel * z;
  if (r < -band) {
    ++a.bin.nearer;
  } else if (r > band) {
    ++a.bin.farther;
  } else {
    ++a.bin.inliers;
    a.r.push_back(static_cast<float>(r));
    a.rc.push_back(static_cast<float>(r - centre));
  }
}

namespace {

// One pixel into a silhouette bin: no depth, nearer or farther than the
// object's surface by more than the band, else on it.
void tally(SilhouetteBin& b, bool missing, bool nearer, bool farther) {
  ++b.n;
  if (missing) ++b.missing;
  else if (nearer) ++b.nearer;
  else if (farther) ++b.farther;
  else ++b.object;
}

}  // namespace

std::vector<double> SensorStatsAccumulator::instance_centres(const DepthImage& measured, const RenderOutput& truth,
                                                             size_t instances) const {
  std::vector<std::vector<float>> inst_r(instances);
  for (size_t p = 0; p < truth.labels.size(); ++p) {
    const int label = truth.labels[p];
    if (label < 0 || !(measured.z[p] > 0)) continue;
    const double zt = truth.depth.z[p], r = measured.z[p] - zt;
    if (std::abs(r) <= s_.outlier_mm + s_.outlier_rel * zt) inst_r[label].push_back(static_cast<float>(r));
  }
  std::vector<double> centre(instances);
  for (size_t k = 0; k < instances; ++k) centre[k] = median(inst_r[k]);
  return centre;
}

void SensorStatsAccumulator::add(const DepthImage& measured, const RenderOutput& truth, const Intrinsics& K,
                                 const std::vector<int>& obj_ids) {
  const int W = measured.width, H = measured.height;
  ++images_;
  const std::vector<int> inside = inside_edge_distance(truth.labels, W, H, 1 << 20);
  std::vector<int> out_d, out_src;
  outside_distance(truth.labels, W, H, s_.silhouette_px, out_d, out_src);
  const bool have_normals = truth.normals.size() == truth.labels.size();
  const std::vector<double> centre = instance_centres(measured, truth, obj_ids.size());
  for (int v = 0; v < H; ++v)
    for (int u = 0; u < W; ++u) {
      const size_t p = static_cast<size_t>(v) * W + u;
      const double zm = measured.z[p];
      const bool missing = !(zm > 0);
      const int label = truth.labels[p];
      if (label < 0) {
        // Outside the silhouette: like the nearest object pixel's depth?
        if (out_d[p] < 1) continue;
        const double zt = truth.depth.z[out_src[p]];
        const double band = s_.outlier_mm + s_.outlier_rel * zt;
        tally(sil_[s_.silhouette_px + out_d[p]], missing, zm < zt - band, zm > zt + band);
        continue;
      }
      const double zt = truth.depth.z[p];
      const double r = missing ? 0 : zm - zt, c = centre[label];
      count(all_, r, c, missing, zt);
      count(object_[obj_ids.at(label)], r, c, missing, zt);
      const int di = static_cast<int>(zt / s_.depth_bin_mm);
      if (di >= 0 && di < static_cast<int>(depth_.size())) count(depth_[di], r, c, missing, zt);
      double inc = 0;
      if (have_normals) {
        const Vec3 ray = K.backproject(u, v, 1.0).normalized();
        const auto& n = truth.normals[p];
        const double cos_inc = std::abs(ray.x() * n.x() + ray.y() * n.y() + ray.z() * n.z());
        inc = std::acos(std::min(1.0, cos_inc)) * 180.0 / M_PI;
        count(incidence_[std::min<int>(incidence_.size() - 1, static_cast<int>(inc / s_.incidence_bin_deg))], r, c,
              missing, zt);
      }
      count(edge_[std::min(s_.edge_bins_px - 1, inside[p])], r, c, missing, zt);
      if (inside[p] >= 8 && inc < 45) count(interior_, r, c, missing, zt);
      if (inside[p] < s_.silhouette_px) {
        const double band = s_.outlier_mm + s_.outlier_rel * zt;
        tally(sil_[s_.silhouette_px - inside[p]], missing, r < -band, r > band);
      }
    }
  if (s_.normal_window_px > 0 && truth.normals.size() == truth.labels.size()) add_normals(measured, truth, K);
  add_quantization(measured);
}

void SensorStatsAccumulator::add_quantization(const DepthImage& measured) {
  std::vector<std::vector<float>> vals(depth_.size());
  for (float z : measured.z) {
    if (!(z > 0)) continue;
    const int di = static_cast<int>(z / s_.depth_bin_mm);
    if (di >= 0 && di < static_cast<int>(vals.size())) vals[di].push_back(z);
  }
  for (size_t i = 0; i < vals.size(); ++i) {
    auto& x = vals[i];
    std::sort(x.begin(), x.end());
    x.erase(std::unique(x.begin(), x.end(), [](float a, float b) { return std::abs(a - b) < 1e-3f; }), x.end());
    if (static_cast<int>(x.size()) < s_.min_quant_values) continue;
    std::vector<double> gaps;
    for (size_t k = 1; k < x.size(); ++k) gaps.push_back(x[k] - x[k - 1]);
    quant_steps_[i].push_back(median(gaps));
  }
}

void SensorStatsAccumulator::add_normals(const DepthImage& measured, const RenderOutput& truth, const Intrinsics& K) {
  const int W = measured.width, H = measured.height, w = s_.normal_window_px;
  const int step = std::max(1, s_.normal_stride);
  for (int v = w; v < H - w; v += step)
    for (int u = w; u < W - w; u += step) {
      const size_t p = static_cast<size_t>(v) * W + u;
      const int label = truth.labels[p];
      if (label < 0 || !(measured.z[p] > 0)) continue;
      const double zt = truth.depth.z[p], band = s_.outlier_mm + s_.outlier_rel * zt;
      if (std::abs(measured.z[p] - zt) > band) continue;
      // The window's measured points of the same object near the pixel's depth.
      Vec3 c = Vec3::Zero();
      std::vector<Vec3> pts;
      for (int dv = -w; dv <= w; ++dv)
        for (int du = -w; du <= w; ++du) {
          const size_t q = static_cast<size_t>(v + dv) * W + (u + du);
          if (truth.labels[q] != label || !(measured.z[q] > 0) || std::abs(measured.z[q] - measured.z[p]) > band)
            continue;
          pts.push_back(K.backproject(u + du, v + dv, measured.z[q]));
          c += pts.back();
        }
      if (static_cast<int>(pts.size()) < (2 * w + 1) * (2 * w + 1) / 2) continue;
      c /= static_cast<double>(pts.size());
      Mat3 C = Mat3::Zero();
      for (const Vec3& x : pts) C += (x - c) * (x - c).transpose();
      const Vec3 n = Eigen::SelfAdjointEigenSolver<Mat3>(C).eigenvectors().col(0);
      const Vec3 nt = truth.normals[p].cast<double>().normalized();
      const double deg = std::acos(std::min(1.0, std::abs(n.dot(nt)))) * 180.0 / M_PI;
      const int di = static_cast<int>(zt / s_.depth_bin_mm);
      if (di >= 0 && di < static_cast<int>(normal_deg_.size())) normal_deg_[di].push_back(static_cast<float>(deg));
    }
}

SensorStats SensorStatsAccumulator::finish() const {
  SensorStats s;
  s.settings = s_;
  s.images = images_;
  s.all = finish_bin(all_.bin, all_.r, all_.rc);
  s.interior_frontal = finish_bin(interior_.bin, interior_.r, interior_.rc);
  for (const Acc& a : depth_) s.by_depth.push_back(finish_bin(a.bin, a.r, a.rc));
  for (const Acc& a : incidence_) s.by_incidence.push_back(finish_bin(a.bin, a.r, a.rc));
  for (const Acc& a : edge_) s.by_edge_px.push_back(finish_bin(a.bin, a.r, a.rc));
  for (const auto& [id, a] : object_) s.by_object[id] = finish_bin(a.bin, a.r, a.rc);
  s.silhouette = sil_;
  for (size_t i = 0; i < normal_deg_.size(); ++i) {
    if (normal_deg_[i].empty()) continue;
    std::vector<float> x = normal_deg_[i];
    NormalBin b{depth_[i].bin.lo, depth_[i].bin.hi, static_cast<int64_t>(x.size()), median(x), 0};
    std::sort(x.begin(), x.end());
    b.p90_deg = x[static_cast<size_t>(0.9 * (x.size() - 1))];
    s.normal_error.push_back(b);
  }
  for (size_t i = 0; i < depth_.size(); ++i) {
    QuantBin q{depth_[i].bin.lo, depth_[i].bin.hi, static_cast<int>(quant_steps_[i].size()), 0};
    q.step_mm = median(quant_steps_[i]);
    s.quantization.push_back(q);
  }
  return s;
}

namespace {

nlohmann::ordered_json bin_json(const ResidualBin& b) {
  nlohmann::ordered_json j;
  j["lo"] = b.lo;
  j["hi"] = b.hi >= 1e9 ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(b.hi);
  j["n"] = b.n;
  j["missing"] = b.missing;
  j["nearer"] = b.nearer;
  j["farther"] = b.farther;
  j["inliers"] = b.inliers;
  j["missing_rate"] = b.missing_rate();
  j["bias_mm"] = b.bias_mm;
  j["spread_mm"] = b.spread_mm;
  return j;
}

}  // namespace

nlohmann::ordered_json to_json(const SensorStats& s) {
  nlohmann::ordered_json j;
  j["settings"] = {{"depth_bin_mm", s.settings.depth_bin_mm},
                   {"incidence_bin_deg", s.settings.incidence_bin_deg},
                   {"outlier_mm", s.settings.outlier_mm},
                   {"outlier_rel", s.settings.outlier_rel},
                   {"silhouette_px", s.settings.silhouette_px}};
  j["images"] = s.images;
  j["all"] = bin_json(s.all);
  j["interior_frontal"] = bin_json(s.interior_frontal);
  auto list = [](const std::vector<ResidualBin>& bins) {
    nlohmann::ordered_json a = nlohmann::ordered_json::array();
    for (const auto& b : bins)
      if (b.n > 0) a.push_back(bin_json(b));
    return a;
  };
  j["by_depth"] = list(s.by_depth);
  j["by_incidence"] = list(s.by_incidence);
  j["by_edge_px"] = list(s.by_edge_px);
  nlohmann::ordered_json obj = nlohmann::ordered_json::object();
  for (const auto& [id, b] : s.by_object) obj[std::to_string(id)] = bin_json(b);
  j["by_object"] = obj;
  nlohmann::ordered_json sil = nlohmann::ordered_json::array();
  for (const auto& b : s.silhouette)
    sil.push_back({{"d", b.d}, {"n", b.n}, {"object", b.object}, {"farther", b.farther}, {"nearer", b.nearer},
                   {"missing", b.missing}, {"object_rate", b.object_rate()}});
  j["silhouette"] = sil;
  nlohmann::ordered_json q = nlohmann::ordered_json::array();
  for (const auto& b : s.quantization)
    if (b.frames > 0) q.push_back({{"lo", b.lo}, {"hi", b.hi}, {"frames", b.frames}, {"step_mm", b.step_mm}});
  j["quantization"] = q;
  nlohmann::ordered_json ne = nlohmann::ordered_json::array();
  for (const auto& b : s.normal_error)
    ne.push_back({{"lo", b.lo}, {"hi", b.hi}, {"n", b.n}, {"median_deg", b.median_deg}, {"p90_deg", b.p90_deg}});
  j["normal_error"] = ne;
  j["settings"]["normal_window_px"] = s.settings.normal_window_px;
  return j;
}

}  // namespace pb
