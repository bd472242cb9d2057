// PNG encoding: the container, libdeflate's zlib streams and our run
// encoder (see png_write.h).
#include "io/png_write.h"

#include <libdeflate.h>

#include <array>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>

namespace pb {

namespace {

// DEFLATE's bits go out least significant first; Huffman codes are defined
// most significant bit first, so they are stored bit-reversed.
class BitWriter {
 public:
  explicit BitWriter(std::vector<unsigned char>& out) : out_(out) {}
  void put(uint32_t bits, int n) {
    acc_ |= static_cast<uint64_t>(bits) << used_;
    used_ += n;
    while (used_ >= 8) {
      out_.push_back(static_cast<unsigned char>(acc_ & 0xFF));
      acc_ >>= 8;
      used_ -= 8;
    }
  }
  void flush() {
    if (used_ > 0) out_.push_back(static_cast<unsigned char>(acc_ & 0xFF));
    acc_ = 0;
    used_ = 0;
  }

 private:
  std::vector<unsigned char>& out_;
  uint64_t acc_ = 0;
  int used_ = 0;
};

uint32_t reversed(uint32_t code, int len) {
  uint32_t r = 0;
  for (int i = 0; i < len; ++i) r |= ((code >> i) & 1u) << (len - 1 - i);
  return r;
}

// The fixed Huffman code of literal/length symbol s (RFC 1951, 3.2.6),
// bit-reversed, and its length.
struct Code {
  uint32_t bits;
  int len;
};
const std::array<Code, 288>& fixed_codes() {
  static const std::array<Code, 288> table = [] {
    std::array<Code, 288> t{};
    for (uint32_t s = 0; s < 288; ++s) {
      Code c;
      if (s < 144) c = {0x30 + s, 8};
      else if (s < 256) c = {0x190 + (s - 144), 9};
      else if (s < 280) c = {s - 256, 7};
      else c = {0xC0 + (s - 280), 8};
      t[s] = {reversed(c.bits, c.len), c.len};
    }
    return t;
  }();
  return table;
}

// Lengths 3..258: symbols 257..285, their base lengths and extra bits.
constexpr std::array<uint16_t, 29> kLengthBase = {3,  4,  5,  6,  7,  8,  9,  10, 11,  13,  15,  17,  19,  23, 27,
                                                  31, 35, 43, 51, 59, 67, 83, 99, 115, 131, 163, 195, 227, 258};
constexpr std::array<uint8_t, 29> kLengthExtra = {0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2,
                                                  2, 3, 3, 3, 3, 4, 4, 4, 4, 5, 5, 5, 5, 0};

void put_symbol(BitWriter& w, uint32_t s) {
  const Code& c = fixed_codes()[s];
  w.put(c.bits, c.len);
}

// A back-reference of `len` (3..258) bytes at distance 1.
void put_repeat(BitWriter& w, uint32_t len) {
  size_t i = kLengthBase.size() - 1;
  while (kLengthBase[i] > len) --i;
  put_symbol(w, 257 + static_cast<uint32_t>(i));
  if (kLengthExtra[i] > 0) w.put(len - kLengthBase[i], kLengthExtra[i]);
  w.put(0, 5);  // distance code 0 (distance 1), five bits, no extra bits
}

void put_be32(std::vector<unsigned char>& out, uint32_t v) {
  for (int k = 3; k >= 0; --k) out.push_back(static_cast<unsigned char>(v >> (8 * k)));
}

// A PNG chunk: length, type, data, CRC-32 of type and data.
void put_chunk(std::vector<unsigned char>& out, const char* type, const unsigned char* data, size_t n) {
  if (n > 0x7FFFFFFFu) throw std::length_error("PNG chunk too large");
  put_be32(out, static_cast<uint32_t>(n));
  const size_t start = out.size();
  out.insert(out.end(), type, type + 4);
  if (n > 0) out.insert(out.end(), data, data + n);
  put_be32(out, static_cast<uint32_t>(libdeflate_crc32(0, out.data() + start, n + 4)));
}

struct CompressorDeleter {
  void operator()(libdeflate_compressor* c) const { libdeflate_free_compressor(c); }
};

// The zlib stream of `raw` by libdeflate at level 1 (one compressor per
// thread, reused).
std::vector<unsigned char> zlib_deflate(const unsigned char* raw, size_t size) {
  thread_local std::unique_ptr<libdeflate_compressor, CompressorDeleter> comp(libdeflate_alloc_compressor(1));
  if (!comp) throw std::bad_alloc();
  std::vector<unsigned char> z(libdeflate_zlib_compress_bound(comp.get(), size));
  const size_t n = libdeflate_zlib_compress(comp.get(), raw, size, z.data(), z.size());
  if (n == 0) throw std::runtime_error("libdeflate: compressed data larger than its bound");
  z.resize(n);
  return z;
}

// The zlib stream of `raw` by the run encoder: header (deflate, 32K window,
// no dictionary), the DEFLATE stream, Adler-32 of the raw bytes.
std::vector<unsigned char> zlib_runs(const unsigned char* raw, size_t size) {
  std::vector<unsigned char> z{0x78, 0x01};
  deflate_runs(raw, size, z);
  put_be32(z, static_cast<uint32_t>(libdeflate_adler32(1, raw, size)));
  return z;
}

}  // namespace

void deflate_runs(const unsigned char* data, size_t n, std::vector<unsigned char>& out) {
  BitWriter w(out);
  w.put(1, 1);  // BFINAL: the only block
  w.put(1, 2);  // BTYPE 01: fixed Huffman codes
  size_t i = 0;
  while (i < n) {
    const unsigned char b = data[i];
    size_t j = i + 1;
    // The run's end: eight bytes at a time, then byte by byte.
    const uint64_t eight = 0x0101010101010101ull * b;
    for (uint64_t w; j + 8 <= n; j += 8) {
      std::memcpy(&w, data + j, 8);
      if (w != eight) break;
    }
    while (j < n && data[j] == b) ++j;
    put_symbol(w, b);
    size_t rest = j - i - 1;
    // Repeats of at most 258 bytes; the last one or two bytes as literals.
    while (rest >= 3) {
      const size_t m = rest < 258 ? rest : 258;
      put_repeat(w, static_cast<uint32_t>(m));
      rest -= m;
    }
    for (; rest > 0; --rest) put_symbol(w, b);
    i = j;
  }
  put_symbol(w, 256);  // end of block
  w.flush();
}

std::vector<unsigned char> encode_png_bytes(uint32_t width, uint32_t height, int bit_depth, int color_type,
                                            const unsigned char* data, size_t rowbytes, PngCompression c) {
  if (width == 0 || height == 0 || width > 0x7FFFFFFFu || height > 0x7FFFFFFFu)
    throw std::invalid_argument("PNG size must be 1..2^31-1 pixels, got " + std::to_string(width) + "x" +
                                std::to_string(height));
  // Each row: its filter type (0, none), then its bytes.
  const size_t size = (rowbytes + 1) * height;
  const std::unique_ptr<unsigned char[]> raw(new unsigned char[size]);  // every byte written below
  for (uint32_t y = 0; y < height; ++y) {
    unsigned char* row = raw.get() + y * (rowbytes + 1);
    row[0] = 0;
    std::memcpy(row + 1, data + y * rowbytes, rowbytes);
  }
  const std::vector<unsigned char> z =
      c == PngCompression::runs ? zlib_runs(raw.get(), size) : zlib_deflate(raw.get(), size);

  std::vector<unsigned char> out{0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  out.reserve(out.size() + 25 + z.size() + 12 + 12);
  std::vector<unsigned char> ihdr;
  put_be32(ihdr, width);
  put_be32(ihdr, height);
  ihdr.push_back(static_cast<unsigned char>(bit_depth));
  ihdr.push_back(static_cast<unsigned char>(color_type));
  ihdr.push_back(0);  // compression: deflate
  ihdr.push_back(0);  // filter method 0
  ihdr.push_back(0);  // no interlace
  put_chunk(out, "IHDR", ihdr.data(), ihdr.size());
  put_chunk(out, "IDAT", z.data(), z.size());
  put_chunk(out, "IEND", nullptr, 0);
  return out;
}

}  // namespace pb
