// ESF's line tracing (global/esf_lines.h). PCL-free.
#include "recognition/global/esf_lines.h"

#include <immintrin.h>

#include <algorithm>
#include <array>
#include <cstdlib>

#include "core/cpu.h"

namespace pb::esf_detail {

namespace {

// One minor coordinate of the traced line: a + (d i / n rounded to nearest,
// halves up) for i = 0, 1, ..., that is a + floor((2 d i + n) / (2 n)),
// exact in integers for negative d too, kept as a remainder 0 <= rem < 2n.
// |2 d| <= 2 n, so one step moves the coordinate by at most one voxel (by
// `stride` in the grid index; branch-free, masks from the sign bit). It
// defines the lines; the tracing reads its moves from MoveTable.
struct Stepper {
  int rem, step, den, stride;
  Stepper(int d, int n, int stride_) : rem(n), step(2 * d), den(2 * n), stride(stride_) {}  // i = 0: n / 2n = 0 rem n
  int next() {  // the index change of this step
    rem += step;
    const int under = rem >> 31;               // -1 when rem < 0
    const int over = (den - 1 - rem) >> 31;    // -1 when rem >= den
    rem += (under & den) - (over & den);
    return (over & stride) - (under & stride);
  }
};

}  // namespace

MoveTable::MoveTable() {
  for (int n = 1; n < kG; ++n)
    for (int d = -n; d <= n; ++d) {
      Stepper s(d, n, 1);
      uint64_t m = 0;
      for (int i = 0; i < n; ++i)
        if (s.next() != 0) m |= uint64_t(1) << i;
      moves_[static_cast<size_t>(n) * (2 * kG + 1) + static_cast<size_t>(d + kG)] = m;
    }
}

const MoveTable& move_table() {
  static const MoveTable t;
  return t;
}

namespace {

// One line's walk: its first voxel, its step count (>= 1) and, per step, the
// major axis's index change plus each minor axis's when its move bit is set.
struct Walk {
  int start, n, major, step1, step2;
  uint64_t moves1, moves2;
};

Walk walk_of(const MoveTable& t, const Eigen::Vector3i& a, const Eigen::Vector3i& b) {
  const Eigen::Vector3i d = b - a;
  const Eigen::Vector3i ad = d.cwiseAbs();
  const int n = std::max({ad.x(), ad.y(), ad.z()});
  const int major = ad.x() == n ? 0 : (ad.y() == n ? 1 : 2);
  const int m1 = major == 0 ? 1 : 0, m2 = major == 2 ? 1 : 2;
  Walk w;
  w.start = OccupancyGrid::index(a.x(), a.y(), a.z());
  w.n = n;
  w.major = (d[major] > 0 ? 1 : -1) * OccupancyGrid::stride(major);
  w.step1 = (d[m1] > 0 ? 1 : -1) * OccupancyGrid::stride(m1);
  w.step2 = (d[m2] > 0 ? 1 : -1) * OccupancyGrid::stride(m2);
  w.moves1 = t(d[m1], n);
  w.moves2 = t(d[m2], n);
  return w;
}

// Eight walks of lengths n[0..7] (0: an unused lane), their occupied voxel
// counts into occupied[0..7]: trace()'s loop in eight lanes, each reading
// its voxel's bit by a masked gather while its step i is below its n.
__attribute__((target("avx2"))) void walk8(const uint32_t* words, const Walk* const* w, int* occupied) {
  alignas(32) int start[8], n[8], major[8], s1[8], s2[8];
  alignas(32) uint32_t lo1[8], hi1[8], lo2[8], hi2[8];
  int steps = 0;
  for (int l = 0; l < 8; ++l) {
    const Walk* x = w[l];
    start[l] = x ? x->start : 0;
    n[l] = x ? x->n : 0;
    major[l] = x ? x->major : 0;
    s1[l] = x ? x->step1 : 0;
    s2[l] = x ? x->step2 : 0;
    lo1[l] = x ? static_cast<uint32_t>(x->moves1) : 0;
    hi1[l] = x ? static_cast<uint32_t>(x->moves1 >> 32) : 0;
    lo2[l] = x ? static_cast<uint32_t>(x->moves2) : 0;
    hi2[l] = x ? static_cast<uint32_t>(x->moves2 >> 32) : 0;
    steps = std::max(steps, n[l]);
  }
#define PB_LOAD(p) _mm256_load_si256(reinterpret_cast<const __m256i*>(p))
  __m256i idx = PB_LOAD(start);
  const __m256i len = PB_LOAD(n), vmajor = PB_LOAD(major), vs1 = PB_LOAD(s1), vs2 = PB_LOAD(s2);
  const __m256i vlo1 = PB_LOAD(lo1), vhi1 = PB_LOAD(hi1), vlo2 = PB_LOAD(lo2), vhi2 = PB_LOAD(hi2);
#undef PB_LOAD
  const __m256i one = _mm256_set1_epi32(1), low5 = _mm256_set1_epi32(31), zero = _mm256_setzero_si256();
  __m256i occ = zero;
  for (int i = 0; i < steps; ++i) {
    const __m256i active = _mm256_cmpgt_epi32(len, _mm256_set1_epi32(i));
    const __m256i word = _mm256_mask_i32gather_epi32(zero, reinterpret_cast<const int*>(words),
                                                     _mm256_srli_epi32(idx, 5), active, 4);
    const __m256i bit = _mm256_and_si256(_mm256_srlv_epi32(word, _mm256_and_si256(idx, low5)), one);
    occ = _mm256_add_epi32(occ, _mm256_and_si256(bit, active));
    const __m128i shift = _mm_cvtsi32_si128(i & 31);
    const __m256i b1 = _mm256_and_si256(_mm256_srl_epi32(i < 32 ? vlo1 : vhi1, shift), one);
    const __m256i b2 = _mm256_and_si256(_mm256_srl_epi32(i < 32 ? vlo2 : vhi2, shift), one);
    const __m256i move = _mm256_add_epi32(_mm256_and_si256(_mm256_sub_epi32(zero, b1), vs1),
                                          _mm256_and_si256(_mm256_sub_epi32(zero, b2), vs2));
    idx = _mm256_add_epi32(idx, _mm256_add_epi32(vmajor, move));
  }
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(occupied), occ);
}

}  // namespace

void trace_lines(const OccupancyGrid& g, const Eigen::Vector3i* from, const Eigen::Vector3i* to, size_t n, Line* out,
                 bool plain) {
  const MoveTable& t = move_table();
  if (plain || !cpu_has_avx2()) {
    for (size_t k = 0; k < n; ++k) out[k] = trace(g, t, from[k], to[k]);
    return;
  }
  // Lines of one voxel as trace() has them; the others walked eight at a
  // time, in order of length (a counting sort over lengths 1..kG-1). The
  // scratch arrays stay with the thread from batch to batch.
  thread_local std::vector<Walk> walks;
  thread_local std::vector<uint32_t> order;
  walks.resize(n);
  order.resize(n);
  std::array<uint32_t, kG + 1> first{};  // first[len]: where lines of that length start in order
  size_t walked = 0;
  for (size_t k = 0; k < n; ++k) {
    if (from[k] == to[k]) {
      out[k] = trace(g, t, from[k], to[k]);
      walks[k].n = 0;
      continue;
    }
    walks[k] = walk_of(t, from[k], to[k]);
    ++first[static_cast<size_t>(walks[k].n)];
    ++walked;
  }
  uint32_t at = 0;
  for (auto& f : first) {
    const uint32_t c = f;
    f = at;
    at += c;
  }
  for (size_t k = 0; k < n; ++k)
    if (walks[k].n > 0) order[first[static_cast<size_t>(walks[k].n)]++] = static_cast<uint32_t>(k);
  const Walk* lanes[8];
  int occupied[8];
  for (size_t b = 0; b < walked; b += 8) {
    const size_t used = std::min<size_t>(8, walked - b);
    for (size_t l = 0; l < 8; ++l) lanes[l] = l < used ? &walks[order[b + l]] : nullptr;
    walk8(g.words(), lanes, occupied);
    for (size_t l = 0; l < used; ++l) {
      const uint32_t k = order[b + l];
      out[k] = classified(walks[k].n, occupied[l]);
    }
  }
}

}  // namespace pb::esf_detail
