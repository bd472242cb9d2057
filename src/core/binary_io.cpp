#include "core/binary_io.h"

namespace pb {

void BinaryWriter::points(const std::vector<Vec3f>& p) {
  pod<uint64_t>(p.size() * 3);
  for (const Vec3f& x : p) {
    const float f[3] = {x.x(), x.y(), x.z()};
    raw(f, sizeof f);
  }
}

void BinaryWriter::pose(const Pose& T) {
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) pod<double>(T.R(r, c));
  for (int r = 0; r < 3; ++r) pod<double>(T.t[r]);
}

std::string BinaryReader::bytes() {
  const uint64_t n = pod<uint64_t>();
  need(n);
  std::string s = buf_.substr(pos_, n);
  pos_ += n;
  return s;
}

std::vector<Vec3f> BinaryReader::points() {
  const std::vector<float> f = vec<float>();
  if (f.size() % 3) fail("point array length is not a multiple of 3");
  std::vector<Vec3f> p(f.size() / 3);
  for (size_t i = 0; i < p.size(); ++i) p[i] = Vec3f(f[3 * i], f[3 * i + 1], f[3 * i + 2]);
  return p;
}

Pose BinaryReader::pose() {
  Pose T;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) T.R(r, c) = pod<double>();
  for (int r = 0; r < 3; ++r) T.t[r] = pod<double>();
  return T;
}

void BinaryReader::expect(const char* magic, size_t n, const std::string& what) {
  need(n);
  if (std::memcmp(buf_.data() + pos_, magic, n) != 0) fail("not a " + what + " (bad magic)");
  pos_ += n;
}

}  // namespace pb
