// PNG encoding (io/png.cpp writes every PNG through it; reading stays with
// libpng). The file is the PNG signature, IHDR, one IDAT and IEND; every row
// has filter type 0 (none). The IDAT's zlib stream comes from one of two
// compressors:
// - deflate: libdeflate at level 1, for noisy content (depth, previews);
// - runs: our own, for images made of long runs of one byte value, as BOP
//   masks are: each run is one literal and then back-references of
//   distance 1 (up to 258 bytes each), in one block of DEFLATE's fixed
//   Huffman codes (RFC 1951, 3.2.6). Its cost grows with the number of runs,
//   not of pixels, beyond one pass to find them.
// Both are deterministic: the same pixels give the same bytes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace pb {

enum class PngCompression { deflate, runs };

// The PNG of `height` rows of `rowbytes` bytes each (8-bit samples, or
// 16-bit big-endian ones as PNG stores them); color_type as PNG's IHDR.
std::vector<unsigned char> encode_png_bytes(uint32_t width, uint32_t height, int bit_depth, int color_type,
                                            const unsigned char* data, size_t rowbytes, PngCompression c);

// The raw DEFLATE stream (RFC 1951, no zlib header) of `n` bytes encoded as
// runs (see above); appended to `out`. Exposed for its tests.
void deflate_runs(const unsigned char* data, size_t n, std::vector<unsigned char>& out);

}  // namespace pb
