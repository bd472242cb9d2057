// PNG files: read through libpng, written by io/png_write.h. libpng reports
// errors with longjmp: every call that can fail runs inside a small C-style
// function holding the setjmp, with no C++ object created between setjmp and
// the libpng calls, and the error text is copied to a plain buffer before
// jumping. The C++ side then throws an InputError naming the file. Images are
// encoded in memory and written with atomic_write_bytes (temp + rename), so a
// reader never sees half a PNG.
#include "io/png.h"

#include <png.h>

#include <cerrno>
#include <cmath>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <fstream>

#include "core/error.h"
#include "core/file_lock.h"
#include "core/round.h"
#include "io/png_write.h"

namespace pb {

namespace {

struct PngErr {
  jmp_buf jump;
  char msg[256];
};

void on_error(png_structp png, png_const_charp msg) {
  auto* e = static_cast<PngErr*>(png_get_error_ptr(png));
  std::snprintf(e->msg, sizeof(e->msg), "%s", msg ? msg : "libpng error");
  longjmp(e->jump, 1);
}
void on_warning(png_structp, png_const_charp) {}

struct MemReader {
  const unsigned char* data;
  size_t size;
  size_t pos;
};

void mem_read(png_structp png, png_bytep out, png_size_t n) {
  auto* r = static_cast<MemReader*>(png_get_io_ptr(png));
  if (r->pos + n > r->size) png_error(png, "unexpected end of file (truncated PNG)");
  std::memcpy(out, r->data + r->pos, n);
  r->pos += n;
}

// Raw decoded image: header fields and 8-bit or big-endian 16-bit rows.
struct Decoded {
  png_uint_32 width = 0, height = 0;
  int bit_depth = 0, color_type = 0, channels = 0;
  std::vector<unsigned char> pixels;  // rows of `rowbytes`
  size_t rowbytes = 0;
  std::vector<png_bytep> rows;
};

// Sets err->msg for an error before libpng could report one; returns false.
bool fail(PngErr* err, const char* msg) {
  std::snprintf(err->msg, sizeof(err->msg), "%s", msg);
  return false;
}

// Decodes `src`; returns false with err->msg set on any libpng error
// (truncated data included).
bool decode(const MemReader& src, Decoded* out, PngErr* err) {
  MemReader reader = src;
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, err, on_error, on_warning);
  if (!png) return fail(err, "cannot create the PNG reader");
  png_infop info = png_create_info_struct(png);
  if (!info) {
    png_destroy_read_struct(&png, nullptr, nullptr);
    return fail(err, "cannot create the PNG reader");
  }
  if (setjmp(err->jump)) {
    png_destroy_read_struct(&png, &info, nullptr);
    return false;
  }
  png_set_read_fn(png, &reader, mem_read);
  // Refuse absurd headers before allocating (a corrupt or hostile file).
  png_set_user_limits(png, 1u << 15, 1u << 15);
  png_read_info(png, info);
  out->width = png_get_image_width(png, info);
  out->height = png_get_image_height(png, info);
  out->bit_depth = png_get_bit_depth(png, info);
  out->color_type = png_get_color_type(png, info);
  out->channels = png_get_channels(png, info);
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  out->rowbytes = png_get_rowbytes(png, info);
  // The vectors live in the caller's frame: resizing them here is safe
  // across a longjmp (their state stays valid, the caller owns them).
  out->pixels.resize(out->rowbytes * out->height);
  out->rows.resize(out->height);
  for (png_uint_32 y = 0; y < out->height; ++y) out->rows[y] = out->pixels.data() + y * out->rowbytes;
  png_read_image(png, out->rows.data());
  png_read_end(png, nullptr);
  png_destroy_read_struct(&png, &info, nullptr);
  return true;
}

std::vector<unsigned char> read_all(const std::string& path, const std::string& field) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, field, std::string("cannot open PNG file: ") + std::strerror(errno));
  std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw InputError(path, field, "read error");
  return bytes;
}

void check_signature(const std::vector<unsigned char>& bytes, const std::string& path, const std::string& field) {
  if (bytes.size() < 8 || png_sig_cmp(bytes.data(), 0, 8) != 0)
    throw InputError(path, field, "not a PNG file");
}

std::string color_name(int color_type) {
  switch (color_type) {
    case PNG_COLOR_TYPE_GRAY: return "gray";
    case PNG_COLOR_TYPE_GRAY_ALPHA: return "gray+alpha";
    case PNG_COLOR_TYPE_RGB: return "RGB";
    case PNG_COLOR_TYPE_RGB_ALPHA: return "RGBA";
    case PNG_COLOR_TYPE_PALETTE: return "palette";
    default: return "color type " + std::to_string(color_type);
  }
}

std::vector<unsigned char> encode_png(const std::string& path, int width, int height, int bit_depth, int color_type,
                                      int channels, const unsigned char* data, const std::string& field,
                                      PngCompression compression = PngCompression::deflate) {
  if (width <= 0 || height <= 0) throw InputError(path, field, "image has no pixels");
  const size_t rowbytes = static_cast<size_t>(width) * channels * (bit_depth / 8);
  try {
    return encode_png_bytes(static_cast<uint32_t>(width), static_cast<uint32_t>(height), bit_depth, color_type, data,
                            rowbytes, compression);
  } catch (const std::exception& e) {
    throw InputError(path, field, std::string("cannot encode PNG: ") + e.what());
  }
}

void write_png(const std::string& path, int width, int height, int bit_depth, int color_type, int channels,
               const unsigned char* data, const std::string& field,
               PngCompression compression = PngCompression::deflate) {
  const auto out = encode_png(path, width, height, bit_depth, color_type, channels, data, field, compression);
  atomic_write_bytes(path, out.data(), out.size());
}

// Reads and decodes a PNG that must be single-channel gray with `bit_depth`
// bits; `expected` says what was wanted in the error message.
Decoded read_gray_png(const std::string& path, const std::string& field, int bit_depth,
                      const std::string& expected) {
  const auto bytes = read_all(path, field);
  check_signature(bytes, path, field);
  Decoded d;
  PngErr err{};
  if (!decode(MemReader{bytes.data(), bytes.size(), 0}, &d, &err))
    throw InputError(path, field, std::string("broken PNG: ") + err.msg);
  if (d.color_type != PNG_COLOR_TYPE_GRAY || d.bit_depth != bit_depth)
    throw InputError(path, field,
                     expected + ", got " + std::to_string(d.bit_depth) + "-bit " + color_name(d.color_type));
  return d;
}

}  // namespace

DepthImage read_depth_png(const std::string& path, double depth_scale) {
  if (!(depth_scale > 0) || !std::isfinite(depth_scale))
    throw InputError(path, "depth_scale", "must be positive, got " + std::to_string(depth_scale));
  const Decoded d = read_gray_png(path, "depth", 16, "expected a 16-bit single-channel (gray) depth PNG");
  DepthImage img(static_cast<int>(d.width), static_cast<int>(d.height));
  for (png_uint_32 y = 0; y < d.height; ++y) {
    const unsigned char* row = d.rows[y];
    for (png_uint_32 x = 0; x < d.width; ++x) {
      const unsigned v = (static_cast<unsigned>(row[2 * x]) << 8) | row[2 * x + 1];  // PNG: big-endian
      img.z[static_cast<size_t>(y) * d.width + x] = static_cast<float>(v * depth_scale);
    }
  }
  return img;
}

void write_depth_png(const std::string& path, const DepthImage& depth, double depth_scale) {
  if (!(depth_scale > 0) || !std::isfinite(depth_scale))
    throw InputError(path, "depth_scale", "must be positive, got " + std::to_string(depth_scale));
  if (depth.z.size() != static_cast<size_t>(depth.width) * depth.height || depth.width <= 0 || depth.height <= 0)
    throw InputError(path, "depth", "image size does not match its pixel count");
  std::vector<unsigned char> buf(depth.z.size() * 2);
  for (size_t i = 0; i < depth.z.size(); ++i) {
    const double z = depth.z[i];
    long v = 0;
    if (z != 0.0) {
      const double q = round_half_away(z / depth_scale);
      if (!std::isfinite(z) || z < 0 || q > 65535.0)
        throw InputError(path, "depth",
                         "pixel (" + std::to_string(i % depth.width) + ", " + std::to_string(i / depth.width) +
                             ") = " + std::to_string(z) + " mm does not fit in 16 bits with depth_scale " +
                             std::to_string(depth_scale));
      v = static_cast<long>(q);
    }
    buf[2 * i] = static_cast<unsigned char>(v >> 8);
    buf[2 * i + 1] = static_cast<unsigned char>(v & 0xff);
  }
  write_png(path, depth.width, depth.height, 16, PNG_COLOR_TYPE_GRAY, 1, buf.data(), "depth");
}

std::vector<uint8_t> read_gray8_png(const std::string& path, int* width, int* height) {
  const Decoded d = read_gray_png(path, "image", 8, "expected an 8-bit gray PNG");
  std::vector<uint8_t> px(static_cast<size_t>(d.width) * d.height);
  for (png_uint_32 y = 0; y < d.height; ++y) std::memcpy(px.data() + y * d.width, d.rows[y], d.width);
  *width = static_cast<int>(d.width);
  *height = static_cast<int>(d.height);
  return px;
}

void write_gray8_png(const std::string& path, int width, int height, const std::vector<uint8_t>& px) {
  if (px.size() != static_cast<size_t>(width) * height)
    throw InputError(path, "image", "pixel count does not match width x height");
  write_png(path, width, height, 8, PNG_COLOR_TYPE_GRAY, 1, px.data(), "image", PngCompression::runs);
}

void write_rgb8_png(const std::string& path, int width, int height, const std::vector<uint8_t>& rgb) {
  if (rgb.size() != static_cast<size_t>(width) * height * 3)
    throw InputError(path, "image", "pixel count does not match width x height x 3");
  write_png(path, width, height, 8, PNG_COLOR_TYPE_RGB, 3, rgb.data(), "image");
}

std::string encode_rgb8_png(int width, int height, const std::vector<uint8_t>& rgb) {
  if (rgb.size() != static_cast<size_t>(width) * height * 3)
    throw InputError("", "image", "pixel count does not match width x height x 3");
  const auto out = encode_png("", width, height, 8, PNG_COLOR_TYPE_RGB, 3, rgb.data(), "image");
  return std::string(out.begin(), out.end());
}

PngHeader read_png_header(const std::string& path) {
  // Signature (8 bytes), then the IHDR chunk: length, "IHDR", width, height
  // (big-endian), bit depth, color type.
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "image", std::string("cannot open PNG file: ") + std::strerror(errno));
  std::vector<unsigned char> b(26, 0);
  in.read(reinterpret_cast<char*>(b.data()), 26);
  if (in.gcount() < 8 || png_sig_cmp(b.data(), 0, 8) != 0) throw InputError(path, "image", "not a PNG file");
  if (in.gcount() < 26 || std::memcmp(b.data() + 12, "IHDR", 4) != 0)
    throw InputError(path, "image", "broken PNG: no IHDR header");
  auto be32 = [&](int o) {
    return (static_cast<uint32_t>(b[o]) << 24) | (static_cast<uint32_t>(b[o + 1]) << 16) |
           (static_cast<uint32_t>(b[o + 2]) << 8) | b[o + 3];
  };
  PngHeader h;
  h.width = static_cast<int>(be32(16));
  h.height = static_cast<int>(be32(20));
  h.bit_depth = b[24];
  switch (b[25]) {
    case PNG_COLOR_TYPE_GRAY: h.channels = 1; break;
    case PNG_COLOR_TYPE_GRAY_ALPHA: h.channels = 2; break;
    case PNG_COLOR_TYPE_RGB: h.channels = 3; break;
    case PNG_COLOR_TYPE_RGB_ALPHA: h.channels = 4; break;
    case PNG_COLOR_TYPE_PALETTE: h.channels = 1; break;
    default: throw InputError(path, "image", "broken PNG: unknown color type");
  }
  if (h.width <= 0 || h.height <= 0) throw InputError(path, "image", "broken PNG: empty image");
  return h;
}

void atomic_write_bytes(const std::string& path, const void* data, size_t size) {
  const std::string tmp = unique_temp_path(path);  // concurrent writers of one path never share a temp file
  std::FILE* f = std::fopen(tmp.c_str(), "wb");
  if (!f) throw InputError(path, "output", std::string("cannot write file: ") + std::strerror(errno));
  const size_t n = size ? std::fwrite(data, 1, size, f) : 0;
  const bool ok = n == size && std::fflush(f) == 0;
  const int werr = errno;
  if (std::fclose(f) != 0 || !ok) {
    std::remove(tmp.c_str());
    throw InputError(path, "output", std::string("cannot write file: ") + std::strerror(werr));
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const int rerr = errno;
    std::remove(tmp.c_str());
    throw InputError(path, "output", std::string("cannot move the file into place: ") + std::strerror(rerr));
  }
}

void atomic_write_text(const std::string& path, const std::string& text) {
  atomic_write_bytes(path, text.data(), text.size());
}

}  // namespace pb
