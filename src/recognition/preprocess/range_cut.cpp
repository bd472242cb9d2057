// The range cut (internal.h): the valid pixels of an organized cloud within
// a depth range, with their pixel indices. Eight pixels at a time with AVX2
// where the CPU has it, for the common case of eight kept pixels in a row;
// any other group of eight takes the one-pixel loop, so both paths keep the
// same pixels in the same order.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "core/cpu.h"
#include "recognition/preprocess/internal.h"

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define PB_RANGE_CUT_X86 1
#endif

namespace pb::detail {

namespace {

static_assert(sizeof(Vec3f) == 3 * sizeof(float), "points are read as packed float triples");

// The box of the kept points so far: lo x y z, hi x y z.
struct Box {
  float v[6] = {std::numeric_limits<float>::infinity(), std::numeric_limits<float>::infinity(),
                std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity(),
                -std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity()};
  void add(const Vec3f& p) {
    for (int d = 0; d < 3; ++d) {
      v[d] = std::min(v[d], p[d]);
      v[3 + d] = std::max(v[3 + d], p[d]);
    }
  }
};

// Pixels [i, end) one at a time, appended at m (returns the new m). Every
// pixel is written and the count advanced only for those kept (no branch
// but the box's).
size_t cut_scalar(const OrganizedCloud& cloud, double min_z, double max_z, const std::vector<char>& drop, size_t i,
                  size_t end, size_t m, Vec3f* pts, int* px, Box& box) {
  for (; i < end; ++i) {
    const Vec3f& p = cloud.points[i];
    const bool keep = std::isfinite(p.x()) && std::isfinite(p.y()) && std::isfinite(p.z()) && !(p.z() < min_z) &&
                      !(p.z() > max_z) && (drop.empty() || !drop[i]);
    pts[m] = p;
    px[m] = static_cast<int>(i);
    if (keep) box.add(p);
    m += keep ? 1 : 0;
  }
  return m;
}

#ifdef PB_RANGE_CUT_X86

// The float bounds that decide z < min_z and z > max_z for every float z as
// the doubles do: z < min_z exactly when z < the smallest float >= min_z,
// and z > max_z exactly when z > the largest float <= max_z.
// A finite double beyond the floats' range is not converted (undefined):
// it gives the float range's end or an infinity, which compare the same.
constexpr double kFloatMax = std::numeric_limits<float>::max();
constexpr float kInf = std::numeric_limits<float>::infinity();
float float_at_least(double v) {
  if (std::isfinite(v) && std::abs(v) > kFloatMax) return v > 0 ? kInf : -std::numeric_limits<float>::max();
  float f = static_cast<float>(v);  // nearest
  if (static_cast<double>(f) < v) f = std::nextafter(f, kInf);
  return f;
}
float float_at_most(double v) {
  if (std::isfinite(v) && std::abs(v) > kFloatMax) return v > 0 ? std::numeric_limits<float>::max() : -kInf;
  float f = static_cast<float>(v);
  if (static_cast<double>(f) > v) f = std::nextafter(f, -kInf);
  return f;
}

// Per float of v: all ones if it is not finite (all exponent bits set) or,
// where zmask is set, a z outside [lo, hi] (the comparisons are false for
// NaN, caught by the first test).
__attribute__((target("avx2"))) inline __m256i bad(__m256 v, __m256i zmask, __m256 lo, __m256 hi, __m256i exp) {
  const __m256i nonfinite = _mm256_cmpeq_epi32(_mm256_and_si256(_mm256_castps_si256(v), exp), exp);
  const __m256 out = _mm256_or_ps(_mm256_cmp_ps(v, lo, _CMP_LT_OQ), _mm256_cmp_ps(v, hi, _CMP_GT_OQ));
  return _mm256_or_si256(nonfinite, _mm256_and_si256(_mm256_castps_si256(out), zmask));
}

// Eight points (24 floats, three vectors) at a time: a group whose every
// coordinate is finite, whose every z lies within the range and whose
// pixels are not dropped is copied as it is; any other group takes
// cut_scalar.
__attribute__((target("avx2"))) size_t cut_avx2(const OrganizedCloud& cloud, double min_z, double max_z,
                                                 const std::vector<char>& drop, Vec3f* pts, int* px, Box& box) {
  const size_t n = cloud.points.size();
  const float* src = cloud.points.front().data();
  const __m256 lo = _mm256_set1_ps(float_at_least(min_z));
  const __m256 hi = _mm256_set1_ps(float_at_most(max_z));
  const __m256i exp = _mm256_set1_epi32(0x7f800000);
  // The z positions among the 24 floats: 2, 5 | 8, 11, 14 | 17, 20, 23.
  const __m256i za = _mm256_setr_epi32(0, 0, -1, 0, 0, -1, 0, 0);
  const __m256i zb = _mm256_setr_epi32(-1, 0, 0, -1, 0, 0, -1, 0);
  const __m256i zc = _mm256_setr_epi32(0, -1, 0, 0, -1, 0, 0, -1);
  const __m256i step = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  // The box of the groups copied whole, per float position of the three
  // vectors (a coordinate repeats every three floats).
  __m256 lo_v[3], hi_v[3];
  for (int k = 0; k < 3; ++k)
    lo_v[k] = _mm256_set1_ps(std::numeric_limits<float>::infinity()),
    hi_v[k] = _mm256_set1_ps(-std::numeric_limits<float>::infinity());
  size_t m = 0, i = 0;
  for (; i + 8 <= n; i += 8) {
    const float* s = src + 3 * i;
    const __m256 a = _mm256_loadu_ps(s), b = _mm256_loadu_ps(s + 8), c = _mm256_loadu_ps(s + 16);
    const __m256i any =
        _mm256_or_si256(_mm256_or_si256(bad(a, za, lo, hi, exp), bad(b, zb, lo, hi, exp)), bad(c, zc, lo, hi, exp));
    uint64_t dropped = 0;
    if (!drop.empty()) std::memcpy(&dropped, drop.data() + i, sizeof dropped);
    if (!_mm256_testz_si256(any, any) || dropped != 0) {
      m = cut_scalar(cloud, min_z, max_z, drop, i, i + 8, m, pts, px, box);
      continue;
    }
    lo_v[0] = _mm256_min_ps(lo_v[0], a), lo_v[1] = _mm256_min_ps(lo_v[1], b), lo_v[2] = _mm256_min_ps(lo_v[2], c);
    hi_v[0] = _mm256_max_ps(hi_v[0], a), hi_v[1] = _mm256_max_ps(hi_v[1], b), hi_v[2] = _mm256_max_ps(hi_v[2], c);
    float* d = pts[m].data();
    _mm256_storeu_ps(d, a);
    _mm256_storeu_ps(d + 8, b);
    _mm256_storeu_ps(d + 16, c);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(px + m),
                        _mm256_add_epi32(_mm256_set1_epi32(static_cast<int>(i)), step));
    m += 8;
  }
  alignas(32) float lows[24], highs[24];
  for (int k = 0; k < 3; ++k) _mm256_store_ps(lows + 8 * k, lo_v[k]), _mm256_store_ps(highs + 8 * k, hi_v[k]);
  for (int f = 0; f < 24; ++f) {  // float f of a group is coordinate f % 3
    box.v[f % 3] = std::min(box.v[f % 3], lows[f]);
    box.v[3 + f % 3] = std::max(box.v[3 + f % 3], highs[f]);
  }
  return cut_scalar(cloud, min_z, max_z, drop, i, n, m, pts, px, box);
}

#endif

}  // namespace

OrganizedCloud every_nth_pixel(const OrganizedCloud& cloud, int n, std::vector<char>& drop) {
  OrganizedCloud out;
  out.width = (cloud.width + n - 1) / n;
  out.height = (cloud.height + n - 1) / n;
  out.points.reserve(static_cast<size_t>(out.width) * static_cast<size_t>(out.height));
  std::vector<char> kept;
  if (!drop.empty()) kept.reserve(out.points.capacity());
  for (int y = 0; y < cloud.height; y += n)
    for (int x = 0; x < cloud.width; x += n) {
      const size_t i = static_cast<size_t>(y) * static_cast<size_t>(cloud.width) + static_cast<size_t>(x);
      out.points.push_back(cloud.points[i]);
      if (!drop.empty()) kept.push_back(drop[i]);
    }
  drop.swap(kept);
  return out;
}

PointSet range_cut(const OrganizedCloud& cloud, double min_z, double max_z, const std::vector<char>& drop,
                   RangeCutIsa isa, float* box) {
  PointSet ps;
  ps.source_width = cloud.width;
  ps.source_height = cloud.height;
  const size_t n = cloud.points.size();
  ps.points.resize(n);
  ps.pixel.resize(n);
  size_t m = 0;
  Box b;
#ifdef PB_RANGE_CUT_X86
  // A NaN bound keeps no pixel in the scalar loop's comparisons either way;
  // the vector path needs ordered float bounds.
  if (isa == RangeCutIsa::best && cpu_has_avx2() && !std::isnan(min_z) && !std::isnan(max_z) && n > 0)
    m = cut_avx2(cloud, min_z, max_z, drop, ps.points.data(), ps.pixel.data(), b);
  else
#endif
    m = cut_scalar(cloud, min_z, max_z, drop, 0, n, 0, ps.points.data(), ps.pixel.data(), b);
  if (box) std::copy(b.v, b.v + 6, box);
  ps.points.resize(m);
  ps.pixel.resize(m);
  return ps;
}

}  // namespace pb::detail
