// SHOT's histogram votes, one and four at a time (shot_votes.h).
#include "recognition/local/shot_votes.h"

#include <algorithm>
#include <cmath>

#include "core/cpu.h"
#include "core/trig.h"
#include "recognition/local/internal.h"

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>

#include "core/trig_avx2.h"
#define PB_SHOT_VOTES_X86 1
#endif

namespace pb::local {

namespace {

constexpr int kCosBins = 10;                 // cosine bins per volume (one more slot: cos = 1)
constexpr int kSlots = kCosBins + 1;         // floats per volume
constexpr int kVolumes = kShotDim / kSlots;  // 32
constexpr int kSpare = kShotDim;             // the slot after the histogram
constexpr double kPi = M_PI;
constexpr double kRad45 = kPi / 4, kRad90 = kPi / 2, kRad135 = 3 * kPi / 4, kRad7_8 = 7 * kPi / 8;

// The volume (0..31) of a vote from the signs and orders of its frame
// coordinates (PCL's numbering: azimuth sector in bits 2-4, upper half in
// bit 0, outer shell in bit 1). The flags: y > 0, y == 0, x > 0, x == 0,
// x < 0, x y > 0, |x| >= |y|, |x| > |y|, z > 0, distance > radius / 2.
struct VolumeFlags {
  bool y_pos, y_zero, x_pos, x_zero, x_neg, xy_pos, ax_ge_ay, ax_gt_ay, z_pos, outer;
};
inline int volume_of(const VolumeFlags& b) {
  const int upper_y = b.y_pos || (b.y_zero && b.x_neg);
  const int right_x = b.x_pos || (b.x_zero && b.y_pos);
  int v = ((upper_y << 3) + ((right_x ? !upper_y : upper_y) << 2)) << 1;
  v += (b.xy_pos || b.x_zero) ? (b.ax_ge_ay ? 0 : 4) : (b.ax_gt_ay ? 4 : 0);
  v += b.z_pos ? 1 : 0;
  v += b.outer ? 2 : 0;
  return v;
}

// The share of a vote at a border between two bins (radial shells,
// elevation halves), from the signed distance t to the border's near middle
// in units of the bins' spacing. On the outer side (distance > r/2, incl >
// 90 degrees) beyond the far middle the own bin keeps 1 - t and the
// neighbour gets nothing, else own 1 + t and the neighbour -t; on the inner
// side before the near middle own 1 + t, else own 1 - t and the neighbour t.
// PCL subtracts t where this adds -t: the same bits.
struct Split {
  double own;   // what the vote's own bin gains
  float share;  // what the neighbour gains (+0.0f when none)
  bool any;     // whether the neighbour gains at all
};
inline Split split(bool outer_side, double t, bool past) {
  if (outer_side) return {past ? 1 - t : 1 + t, past ? 0.f : -static_cast<float>(t), !past};
  return {past ? 1 + t : 1 - t, past ? 0.f : static_cast<float>(t), !past};
}

// What one vote adds: up to five (bin, value) pairs in PCL's order; a pair
// that is no addition goes to the spare slot with +0.0f.
struct VoteAdds {
  int bin[5];
  float value[5];
  int n;
};

// The additions of a vote from its lanes' results (shared by both paths):
// the volume, the cosine step and fraction, the radial and elevation
// splits, the azimuth's t (when it has one) and the own bin's total.
inline void collect(int vol, int step, double frac, const Split& rs, bool outer, const Split& es, bool lower,
                    bool has_az, double t_az, double own, VoteAdds* a) {
  const int base = vol * kSlots;
  const bool up = frac > 0;
  a->n = 0;
  a->bin[a->n] = base + (up ? (step + 1) % kCosBins : (step - 1 + kCosBins) % kCosBins);
  a->value[a->n++] = up ? static_cast<float>(frac) : -static_cast<float>(frac);
  a->bin[a->n] = rs.any ? (outer ? vol - 2 : vol + 2) * kSlots + step : kSpare;
  a->value[a->n++] = rs.share;
  a->bin[a->n] = es.any ? (lower ? vol + 1 : vol - 1) * kSlots + step : kSpare;
  a->value[a->n++] = es.share;
  if (has_az) {
    const bool ahead = t_az > 0;
    a->bin[a->n] = (ahead ? (vol + 4) % kVolumes : (vol - 4 + kVolumes) % kVolumes) * kSlots + step;
    a->value[a->n++] = ahead ? static_cast<float>(t_az) : -static_cast<float>(t_az);
  }
  a->bin[a->n] = base + step;
  a->value[a->n++] = static_cast<float>(own);
}

inline void apply(const VoteAdds& a, float* h) {
  for (int k = 0; k < a.n; ++k) h[a.bin[k]] += a.value[k];
}

// Vote i, one at a time (PCL's arithmetic).
void vote_scalar(const ShotVotes& v, size_t i, const ShotFrame& f, double radius, float* h) {
  const double r14 = radius / 4, r12 = radius / 2, r34 = radius * 3 / 4;
  const Vec3f d(v.ox[i], v.oy[i], v.oz[i]);
  const double distance = v.dist[i];
  const double c = std::clamp(static_cast<double>(v.nz[i]), -1.0, 1.0);
  const double bin_pos = ((1.0 + c) * kCosBins) / 2;
  double x = d.dot(f.x), y = d.dot(f.y), z = d.dot(f.z);
  if (std::abs(y) < 1e-30) y = 0;
  if (std::abs(x) < 1e-30) x = 0;
  if (std::abs(z) < 1e-30) z = 0;
  const bool outer = distance > r12;
  const int vol = volume_of({y > 0, y == 0.0, x > 0, x == 0.0, x < 0, x * y > 0, std::abs(x) >= std::abs(y),
                             std::abs(x) > std::abs(y), z > 0, outer});
  // floor(bin_pos + 0.5) for bin_pos in [0, 10]: the truncation.
  const int step = static_cast<int>(bin_pos + 0.5);
  const double frac = bin_pos - step;
  double own = 1 - std::abs(frac);
  const double tr = (distance - (outer ? r34 : r14)) / r12;
  const Split rs = split(outer, tr, outer ? distance > r34 : distance < r14);
  own += rs.own;
  const double incl = series_acos(std::clamp(z / distance, -1.0, 1.0));
  const bool lower = incl > kRad90 || (std::abs(incl - kRad90) < 1e-30 && z <= 0);
  const double te = (incl - (lower ? kRad135 : kRad45)) / kRad90;
  const Split es = split(lower, te, lower ? incl > kRad135 : incl < kRad45);
  own += es.own;
  const bool has_az = y != 0.0 || x != 0.0;
  double t_az = 0;
  if (has_az) {
    const double az = series_atan2_double(y, x);
    t_az = std::clamp((az - (-kRad7_8 + kRad45 * (vol >> 2))) / kRad45, -0.5, 0.5);
    own += t_az > 0 ? 1 - t_az : 1 + t_az;
  }
  VoteAdds a;
  collect(vol, step, frac, rs, outer, es, lower, has_az, t_az, own, &a);
  apply(a, h);
}

#ifdef PB_SHOT_VOTES_X86

// std::clamp(v, lo, hi) per lane: lo below lo, hi above hi, else v (NaN: v).
__attribute__((target("avx2"))) inline __m256d clamp4(__m256d v, double lo, double hi) {
  const __m256d l = _mm256_set1_pd(lo), u = _mm256_set1_pd(hi);
  const __m256d above = _mm256_blendv_pd(v, u, _mm256_cmp_pd(u, v, _CMP_LT_OQ));
  return _mm256_blendv_pd(above, l, _mm256_cmp_pd(v, l, _CMP_LT_OQ));
}

// Eigen's float dot product of a 3-vector, a0 b0 + (a1 b1 + a2 b2), per lane,
// widened to double.
__attribute__((target("avx2"))) inline __m256d dot4(__m128 a0, __m128 a1, __m128 a2, const Vec3f& b) {
  const __m128 s = _mm_add_ps(_mm_mul_ps(a0, _mm_set1_ps(b.x())),
                              _mm_add_ps(_mm_mul_ps(a1, _mm_set1_ps(b.y())), _mm_mul_ps(a2, _mm_set1_ps(b.z()))));
  return _mm256_cvtps_pd(s);
}

// |v| < 1e-30 -> +0 per lane.
__attribute__((target("avx2"))) inline __m256d flush4(__m256d v) {
  const __m256d abs = _mm256_andnot_pd(_mm256_set1_pd(-0.0), v);
  return _mm256_blendv_pd(v, _mm256_setzero_pd(), _mm256_cmp_pd(abs, _mm256_set1_pd(1e-30), _CMP_LT_OQ));
}

inline bool lane(int mask, int l) { return (mask >> l & 1) != 0; }

__attribute__((target("avx2"))) inline int mask(__m256d m) { return _mm256_movemask_pd(m); }

// Lane mask m (bit l: lane l) as a vector of all-ones / zero lanes.
__attribute__((target("avx2"))) inline __m256d bits(int m) {
  return _mm256_castsi256_pd(_mm256_cmpgt_epi64(
      _mm256_and_si256(_mm256_set1_epi64x(m), _mm256_setr_epi64x(1, 2, 4, 8)), _mm256_setzero_si256()));
}

// A split's own share: 1 - t where `minus`, else 1 + t.
__attribute__((target("avx2"))) inline __m256d own_share(__m256d t, __m256d minus) {
  const __m256d one = _mm256_set1_pd(1.0);
  return _mm256_blendv_pd(_mm256_add_pd(one, t), _mm256_sub_pd(one, t), minus);
}

// The same for four float lanes.
__attribute__((target("avx2"))) inline __m128 fbits(int m) {
  return _mm_castsi128_ps(
      _mm_cmpgt_epi32(_mm_and_si128(_mm_set1_epi32(m), _mm_setr_epi32(1, 2, 4, 8)), _mm_setzero_si128()));
}

// v with its sign flipped in the lanes of m (float negation).
__attribute__((target("avx2"))) inline __m128 negate_where(__m128 v, int m) {
  return _mm_xor_ps(v, _mm_and_ps(_mm_set1_ps(-0.0f), fbits(m)));
}

// Four votes' bins and the floats they add, as votes4 computes them in
// lanes: lane l is vote i + l.
struct Votes4 {
  alignas(16) int vol[4];   // the volume
  alignas(16) int step[4];  // the cosine bin
  // The cosine neighbour's, the radial and elevation splits', the
  // azimuth's and the own bin's floats.
  alignas(16) float cosv[4];
  alignas(16) float rv[4];
  alignas(16) float ev[4];
  alignas(16) float av[4];
  alignas(16) float ownf[4];
  // Lane masks: the cosine neighbour is the next bin (else the previous);
  // past the radial middle, on its outer side; past the elevation's
  // middle, on its lower side; an azimuth, ahead of its sector's centre.
  int up, past_r, outer, past_e, lower, has_az, ahead;
};

// The additions of four votes, vote by vote (h: the histogram).
inline void add4(const Votes4& w, float* h) {
  for (int l = 0; l < 4; ++l) {
    const int v = w.vol[l], st = w.step[l], base = v * kSlots;
    h[base + (lane(w.up, l) ? (st + 1) % kCosBins : (st - 1 + kCosBins) % kCosBins)] += w.cosv[l];
    h[lane(w.past_r, l) ? kSpare : (lane(w.outer, l) ? v - 2 : v + 2) * kSlots + st] += w.rv[l];
    h[lane(w.past_e, l) ? kSpare : (lane(w.lower, l) ? v + 1 : v - 1) * kSlots + st] += w.ev[l];
    if (lane(w.has_az, l))
      h[(lane(w.ahead, l) ? (v + 4) % kVolumes : (v - 4 + kVolumes) % kVolumes) * kSlots + st] += w.av[l];
    h[base + st] += w.ownf[l];
  }
}

// Votes i .. i + 3: the arithmetic in lanes (series_acos and
// series_atan2_double too, core/trig_avx2.h), the additions vote by vote.
__attribute__((target("avx2"))) void votes4(const ShotVotes& v, size_t i, const ShotFrame& f, double radius,
                                            float* h) {
  Votes4 w;
  const double r14 = radius / 4, r12 = radius / 2, r34 = radius * 3 / 4;
  const __m128 ox = _mm_loadu_ps(v.ox.data() + i), oy = _mm_loadu_ps(v.oy.data() + i),
               oz = _mm_loadu_ps(v.oz.data() + i);
  const __m256d distance = _mm256_loadu_pd(v.dist.data() + i);
  const __m256d c = clamp4(_mm256_cvtps_pd(_mm_loadu_ps(v.nz.data() + i)), -1.0, 1.0);
  const __m256d bin_pos = _mm256_div_pd(_mm256_mul_pd(_mm256_add_pd(_mm256_set1_pd(1.0), c), _mm256_set1_pd(kCosBins)),
                                        _mm256_set1_pd(2.0));
  const __m256d x = flush4(dot4(ox, oy, oz, f.x)), y = flush4(dot4(ox, oy, oz, f.y)), z = flush4(dot4(ox, oy, oz, f.z));
  const __m256d zero = _mm256_setzero_pd(), sign = _mm256_set1_pd(-0.0);
  const __m256d ax = _mm256_andnot_pd(sign, x), ay = _mm256_andnot_pd(sign, y);
  const int y_pos = mask(_mm256_cmp_pd(y, zero, _CMP_GT_OQ)), y_zero = mask(_mm256_cmp_pd(y, zero, _CMP_EQ_OQ));
  const int x_pos = mask(_mm256_cmp_pd(x, zero, _CMP_GT_OQ)), x_zero = mask(_mm256_cmp_pd(x, zero, _CMP_EQ_OQ));
  const int x_neg = mask(_mm256_cmp_pd(x, zero, _CMP_LT_OQ));
  const int xy_pos = mask(_mm256_cmp_pd(_mm256_mul_pd(x, y), zero, _CMP_GT_OQ));
  const int ax_ge = mask(_mm256_cmp_pd(ax, ay, _CMP_GE_OQ)), ax_gt = mask(_mm256_cmp_pd(ax, ay, _CMP_GT_OQ));
  const int z_pos = mask(_mm256_cmp_pd(z, zero, _CMP_GT_OQ));
  const __m256d outer_m = _mm256_cmp_pd(distance, _mm256_set1_pd(r12), _CMP_GT_OQ);
  const int outer = w.outer = mask(outer_m);
  // The cosine step and fraction.
  int* step = w.step;
  _mm_store_si128(reinterpret_cast<__m128i*>(step), _mm256_cvttpd_epi32(_mm256_add_pd(bin_pos, _mm256_set1_pd(0.5))));
  const __m256d frac = _mm256_sub_pd(bin_pos, _mm256_cvtepi32_pd(_mm_load_si128(reinterpret_cast<__m128i*>(step))));
  __m256d own = _mm256_sub_pd(_mm256_set1_pd(1.0), _mm256_andnot_pd(sign, frac));
  // Radial.
  const __m256d tr = _mm256_div_pd(
      _mm256_sub_pd(distance, _mm256_blendv_pd(_mm256_set1_pd(r14), _mm256_set1_pd(r34), outer_m)),
      _mm256_set1_pd(r12));
  const int past_r = w.past_r = (mask(_mm256_cmp_pd(distance, _mm256_set1_pd(r34), _CMP_GT_OQ)) & outer) |
                     (mask(_mm256_cmp_pd(distance, _mm256_set1_pd(r14), _CMP_LT_OQ)) & ~outer);
  // Elevation.
  const __m256d in = series_acos4(clamp4(_mm256_div_pd(z, distance), -1.0, 1.0));
  const __m256d near90 = _mm256_cmp_pd(_mm256_andnot_pd(sign, _mm256_sub_pd(in, _mm256_set1_pd(kRad90))),
                                       _mm256_set1_pd(1e-30), _CMP_LT_OQ);
  const __m256d lower_m = _mm256_or_pd(_mm256_cmp_pd(in, _mm256_set1_pd(kRad90), _CMP_GT_OQ),
                                       _mm256_and_pd(near90, _mm256_cmp_pd(z, zero, _CMP_LE_OQ)));
  const int lower = w.lower = mask(lower_m);
  const __m256d te = _mm256_div_pd(
      _mm256_sub_pd(in, _mm256_blendv_pd(_mm256_set1_pd(kRad45), _mm256_set1_pd(kRad135), lower_m)),
      _mm256_set1_pd(kRad90));
  const int past_e = w.past_e = (mask(_mm256_cmp_pd(in, _mm256_set1_pd(kRad135), _CMP_GT_OQ)) & lower) |
                     (mask(_mm256_cmp_pd(in, _mm256_set1_pd(kRad45), _CMP_LT_OQ)) & ~lower);
  // The volumes, then the azimuth's t where x or y is not 0.
  int* vol = w.vol;
  for (int l = 0; l < 4; ++l)
    vol[l] = volume_of({lane(y_pos, l), lane(y_zero, l), lane(x_pos, l), lane(x_zero, l), lane(x_neg, l),
                        lane(xy_pos, l), lane(ax_ge, l), lane(ax_gt, l), lane(z_pos, l), lane(outer, l)});
  const __m256d has_az_m = _mm256_or_pd(_mm256_cmp_pd(y, zero, _CMP_NEQ_UQ), _mm256_cmp_pd(x, zero, _CMP_NEQ_UQ));
  w.has_az = mask(has_az_m);
  const __m256d az = _mm256_and_pd(series_atan2_double4(y, x), has_az_m);
  const __m256d sector = _mm256_cvtepi32_pd(_mm_srai_epi32(_mm_load_si128(reinterpret_cast<__m128i*>(vol)), 2));
  const __m256d centre = _mm256_add_pd(_mm256_set1_pd(-kRad7_8), _mm256_mul_pd(_mm256_set1_pd(kRad45), sector));
  const __m256d ta =
      clamp4(_mm256_div_pd(_mm256_sub_pd(az, centre), _mm256_set1_pd(kRad45)), -0.5, 0.5);
  // The own bin's total, in PCL's order: 1 - |frac|, the radial share, the
  // elevation's, the azimuth's. A split's own share is 1 - t on the outer
  // side past the far middle and on the inner side before the near one
  // (outer == past), else 1 + t.
  own = _mm256_add_pd(own, own_share(tr, bits(~(outer ^ past_r) & 15)));
  own = _mm256_add_pd(own, own_share(te, bits(~(lower ^ past_e) & 15)));
  const __m256d ahead_m = _mm256_cmp_pd(ta, zero, _CMP_GT_OQ);
  own = _mm256_blendv_pd(own, _mm256_add_pd(own, own_share(ta, ahead_m)), has_az_m);
  // The floats added: the cosine neighbour's |frac|-signed fraction, the
  // splits' shares (+0 past the middle; -t outside, t inside), the
  // azimuth's, the own bin's total.
  w.up = mask(_mm256_cmp_pd(frac, zero, _CMP_GT_OQ));
  _mm_store_ps(w.cosv, negate_where(_mm256_cvtpd_ps(frac), ~w.up & 15));
  _mm_store_ps(w.rv, _mm_andnot_ps(fbits(past_r), negate_where(_mm256_cvtpd_ps(tr), outer)));
  _mm_store_ps(w.ev, _mm_andnot_ps(fbits(past_e), negate_where(_mm256_cvtpd_ps(te), lower)));
  _mm_store_ps(w.av, negate_where(_mm256_cvtpd_ps(ta), ~mask(ahead_m) & 15));
  _mm_store_ps(w.ownf, _mm256_cvtpd_ps(own));
  w.ahead = mask(ahead_m);
  add4(w, h);
}

#endif

}  // namespace

void add_shot_votes(const ShotVotes& v, const ShotFrame& f, double radius, float* h, ShotVotesIsa isa) {
  size_t i = 0;
#ifdef PB_SHOT_VOTES_X86
  if (isa == ShotVotesIsa::best && cpu_has_avx2())
    for (; i + 4 <= v.size(); i += 4) votes4(v, i, f, radius, h);
#endif
  for (; i < v.size(); ++i) vote_scalar(v, i, f, radius, h);
}

}  // namespace pb::local
