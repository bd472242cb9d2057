// One scalar of a binary file record, little endian: shared by the PLY check
// (binary_little_endian; big endian after a byte swap) and the PCD reader.
#pragma once

#include <cstdint>
#include <cstring>

namespace pb {

// `size` bytes (1, 2, 4 or 8; floats 4 or 8), sign-extended when
// `is_signed`, as a double (integers exact up to 2^53). The caller checks
// that `size` bytes are there.
inline double decode_scalar_le(const unsigned char* p, int size, bool is_float, bool is_signed) {
  if (is_float) {
    if (size == 4) {
      float f;
      std::memcpy(&f, p, 4);
      return f;
    }
    double d;
    std::memcpy(&d, p, 8);
    return d;
  }
  uint64_t u = 0;
  std::memcpy(&u, p, static_cast<size_t>(size));
  const int bits = 8 * size;
  if (is_signed && bits < 64 && ((u >> (bits - 1)) & 1u)) u |= ~uint64_t{0} << bits;  // sign-extend
  return is_signed ? static_cast<double>(static_cast<int64_t>(u)) : static_cast<double>(u);
}

}  // namespace pb
