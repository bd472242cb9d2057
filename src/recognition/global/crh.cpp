// Camera Roll Histogram: pcl::CRHEstimation for the histograms, our phase
// correlation (the algorithm of pcl::CRHAlignment::computeRollAngle, with the
// peak threshold, distance and count from the settings) for the roll angles.
#include <pcl/features/crh.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/recognition/crh_alignment.h>

#include <algorithm>
#include <cmath>

#include "recognition/global/internal.h"

namespace pb::global {

namespace {
constexpr int kCrhBins = 90;
using CrhHistogram = pcl::Histogram<kCrhBins>;

constexpr int kHarm = kCrhBins / 2;  // 45: the Nyquist harmonic
constexpr int kSteps = 360;          // the correlation's samples: one degree

// cos(k th) and sin(k th) at th = 2 pi j / kSteps, for every sample j and
// harmonic k (row j): the correlation's terms depend on the spectra only
// through their weights, so the 16,560 cosines and as many sines are
// computed once per process, by the same expressions (the same bits), not
// per call.
struct Harmonics {
  std::vector<double> c, s;
  Harmonics() : c(kSteps * (kHarm + 1)), s(kSteps * (kHarm + 1)) {
    for (int j = 0; j < kSteps; ++j) {
      const double th = 2 * M_PI * j / kSteps;
      for (int k = 0; k <= kHarm; ++k) {
        c[static_cast<size_t>(j * (kHarm + 1) + k)] = std::cos(k * th);
        s[static_cast<size_t>(j * (kHarm + 1) + k)] = std::sin(k * th);
      }
    }
  }
};
const Harmonics& harmonics() {
  static const Harmonics h;
  return h;
}

pcl::PointCloud<CrhHistogram> to_pcl(const std::vector<float>& v) {
  pcl::PointCloud<CrhHistogram> c;
  c.resize(1);
  for (int i = 0; i < kCrhBins; ++i) c[0].histogram[i] = v[i];
  return c;
}
}  // namespace

Mat3 rotation_to_z(const Vec3& axis) {
  const Vec3 a = axis.normalized();
  return Eigen::Quaterniond::FromTwoVectors(a, Vec3::UnitZ()).toRotationMatrix();
}

std::vector<float> crh_spectrum(const PointSet& cloud, const Vec3f& axis) {
  if (!cloud.has_normals()) return {};
  const Eigen::Matrix3f R = rotation_to_z(axis.cast<double>()).cast<float>();
  pcl::PointCloud<pcl::PointXYZ>::Ptr pts(new pcl::PointCloud<pcl::PointXYZ>);
  pcl::PointCloud<pcl::Normal>::Ptr nrm(new pcl::PointCloud<pcl::Normal>);
  for (size_t i = 0; i < cloud.points.size(); ++i) {
    if (!cloud.points[i].allFinite() || !cloud.normals[i].allFinite()) continue;
    pcl::PointXYZ p;
    p.getVector3fMap() = R * cloud.points[i];
    pcl::Normal q;
    q.getNormalVector3fMap() = R * cloud.normals[i];
    pts->push_back(p);
    nrm->push_back(q);
  }
  if (pts->size() < 3) return {};
  // The cloud is already in the frame where the axis is +z: a centroid on +z
  // makes PCL's own alignment rotation the identity.
  pcl::CRHEstimation<pcl::PointXYZ, pcl::Normal, CrhHistogram> crh;
  crh.setInputCloud(pts);
  crh.setInputNormals(nrm);
  Eigen::Vector4f c(0.f, 0.f, 1.f, 0.f);
  crh.setCentroid(c);
  pcl::PointCloud<CrhHistogram> out;
  crh.compute(out);
  if (out.size() != 1) return {};
  std::vector<float> v(out[0].histogram, out[0].histogram + kCrhBins);
  for (float x : v)
    if (!std::isfinite(x)) return {};
  return v;
}

std::vector<double> crh_roll_peaks(const std::vector<float>& S, const std::vector<float>& V,
                                   const GlobalSettings& s) {
  std::vector<double> peaks;
  if (S.size() != kCrhBins || V.size() != kCrhBins || s.crh_max_peaks <= 0) return peaks;
  // Normalized cross power spectrum P_k = S_k conj(V_k) / |.|; with the
  // scene histogram equal to the view's shifted by theta0, P_k =
  // exp(-i k theta0) and sum_k Re(P_k exp(i k theta)) peaks at theta0.
  std::vector<double> pr(kHarm + 1, 0.0), pi(kHarm + 1, 0.0);
  pr[0] = static_cast<double>(S[0]) * V[0];  // DC, unnormalized as PCL
  for (int k = 1; k < kHarm; ++k) {
    const double a = S[2 * k - 1], b = S[2 * k], c = V[2 * k - 1], d = V[2 * k];
    const double re = a * c + b * d, im = b * c - a * d;
    const double m = std::hypot(re, im);
    if (m > 1e-12) {
      pr[k] = re / m;
      pi[k] = im / m;
    }
  }
  const double ny = static_cast<double>(S[kCrhBins - 1]) * V[kCrhBins - 1];
  pr[kHarm] = ny > 0 ? 1.0 : (ny < 0 ? -1.0 : 0.0);
  const Harmonics& h = harmonics();
  std::vector<double> corr(kSteps);
  for (int j = 0; j < kSteps; ++j) {
    const double* cj = h.c.data() + j * (kHarm + 1);
    const double* sj = h.s.data() + j * (kHarm + 1);
    double sum = 0;
    for (int k = 0; k <= kHarm; ++k) sum += pr[k] * cj[k] - pi[k] * sj[k];
    corr[j] = sum;
  }
  // Local maxima (circular), refined by a parabola through three samples.
  struct Peak {
    double value, deg;
  };
  std::vector<Peak> cand;
  for (int j = 0; j < kSteps; ++j) {
    const double l = corr[(j + kSteps - 1) % kSteps], c = corr[j], r = corr[(j + 1) % kSteps];
    if (c > l && c >= r) {
      const double den = l - 2 * c + r;
      const double off = den < 0 ? std::clamp(0.5 * (l - r) / den, -0.5, 0.5) : 0.0;
      cand.push_back({c, j + off});
    }
  }
  if (cand.empty()) {
    cand.push_back({corr[0], 0.0});  // flat correlation: no information
  }
  std::stable_sort(cand.begin(), cand.end(), [](const Peak& a, const Peak& b) { return a.value > b.value; });
  const double best = cand.front().value;
  std::vector<double> kept_deg;
  for (const auto& p : cand) {
    if (static_cast<int>(kept_deg.size()) >= s.crh_max_peaks) break;
    if (!kept_deg.empty() && !(best > 0 && p.value >= s.crh_peak_threshold * best)) break;
    bool distinct = true;
    for (double d : kept_deg) {
      double diff = std::fmod(std::abs(d - p.deg), 360.0);
      diff = std::min(diff, 360.0 - diff);
      if (diff < s.crh_peak_distance_deg) distinct = false;
    }
    if (!distinct) continue;
    kept_deg.push_back(p.deg);
  }
  for (double d : kept_deg) peaks.push_back(d * M_PI / 180.0);
  return peaks;
}

std::vector<double> pcl_crh_roll_peaks(const std::vector<float>& S, const std::vector<float>& V) {
  std::vector<double> out;
  if (S.size() != kCrhBins || V.size() != kCrhBins) return out;
  auto in = to_pcl(S), target = to_pcl(V);
  pcl::CRHAlignment<pcl::PointXYZ, kCrhBins> align;
  std::vector<float> rolls;
  align.computeRollAngle(in, target, rolls);
  // CRHAlignment rotates by Rz(-roll) (computeRollTransform): theta = -roll.
  for (float r : rolls) out.push_back(-static_cast<double>(r) * M_PI / 180.0);
  return out;
}

}  // namespace pb::global
