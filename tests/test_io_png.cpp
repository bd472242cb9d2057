// PNG reading and writing: exact 16-bit depth round trip, clear InputErrors
// (file + "depth") for 8-bit, RGB, truncated and non-PNG files, atomic writes.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "core/error.h"
#include "core/random.h"
#include "io/png.h"
#include "temp_dir.h"

namespace fs = std::filesystem;
using namespace pb;

namespace {

using pbtest::TempDir;

std::string slurp(const std::string& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

DepthImage test_depth(double scale, uint64_t seed) {
  DepthImage d(37, 23);
  Rng rng(seed);
  for (size_t i = 0; i < d.z.size(); ++i) {
    const int v = rng.uniform_int(0, 65535);
    d.z[i] = static_cast<float>(v * scale);
  }
  d.z[0] = 0.f;
  d.z[1] = static_cast<float>(65535 * scale);
  d.z[2] = static_cast<float>(1 * scale);
  return d;
}

// Expects an InputError whose message names the file and `field`.
template <typename F>
void expect_input_error(F&& f, const std::string& file, const std::string& field) {
  try {
    f();
    ADD_FAILURE() << "no InputError for " << file;
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(file), std::string::npos) << msg;
    EXPECT_NE(msg.find(field), std::string::npos) << msg;
    EXPECT_EQ(e.file(), file);
    EXPECT_EQ(e.field(), field);
  }
}

}  // namespace

TEST(Png, Depth16RoundTripIsExact) {
  TempDir tmp;
  for (double scale : {1.0, 0.1, 0.25}) {
    const DepthImage d = test_depth(scale, 7);
    const std::string p = tmp / "d.png";
    write_depth_png(p, d, scale);
    const DepthImage r = read_depth_png(p, scale);
    ASSERT_EQ(r.width, d.width);
    ASSERT_EQ(r.height, d.height);
    for (size_t i = 0; i < d.z.size(); ++i) ASSERT_EQ(r.z[i], d.z[i]) << "pixel " << i << " scale " << scale;
    // The raw 16-bit values are the depth / depth_scale.
    const DepthImage raw = read_depth_png(p, 1.0);
    EXPECT_EQ(raw.z[1], 65535.f);
    EXPECT_EQ(raw.z[2], 1.f);
    EXPECT_EQ(raw.z[0], 0.f);
    const PngHeader h = read_png_header(p);
    EXPECT_EQ(h.width, 37);
    EXPECT_EQ(h.height, 23);
    EXPECT_EQ(h.bit_depth, 16);
    EXPECT_EQ(h.channels, 1);
  }
  EXPECT_FALSE(fs::exists(tmp / "d.png.tmp"));
}

TEST(Png, SameDepthSameBytes) {
  TempDir tmp;
  const DepthImage d = test_depth(1.0, 3);
  write_depth_png(tmp / "a.png", d, 1.0);
  write_depth_png(tmp / "b.png", d, 1.0);
  EXPECT_EQ(slurp(tmp / "a.png"), slurp(tmp / "b.png"));
}

TEST(Png, DepthRoundsToNearestStep) {
  TempDir tmp;
  DepthImage d(2, 1);
  d.z = {1000.04f, 1000.06f};
  write_depth_png(tmp / "r.png", d, 0.1);
  const DepthImage r = read_depth_png(tmp / "r.png", 1.0);
  EXPECT_EQ(r.z[0], 10000.f);
  EXPECT_EQ(r.z[1], 10001.f);
}

TEST(Png, DepthOutOfRangeIsRejectedAndNothingWritten) {
  TempDir tmp;
  const std::string p = tmp / "big.png";
  DepthImage d(4, 4);
  d.at(3, 2) = 70000.f;  // > 65535 at scale 1
  expect_input_error([&] { write_depth_png(p, d, 1.0); }, p, "depth");
  d.at(3, 2) = -5.f;
  expect_input_error([&] { write_depth_png(p, d, 1.0); }, p, "depth");
  d.at(3, 2) = 7000.f;  // fits at scale 0.1 (70000 steps)? no: 70000 > 65535
  expect_input_error([&] { write_depth_png(p, d, 0.1); }, p, "depth");
  EXPECT_FALSE(fs::exists(p));
  EXPECT_FALSE(fs::exists(p + ".tmp"));
  d.at(3, 2) = 6553.5f;  // exactly 65535 steps of 0.1
  write_depth_png(p, d, 0.1);
  EXPECT_EQ(read_depth_png(p, 1.0).at(3, 2), 65535.f);
}

TEST(Png, EightBitGrayIsNotDepth) {
  TempDir tmp;
  const std::string p = tmp / "gray8.png";
  std::vector<uint8_t> px(6 * 5);
  for (size_t i = 0; i < px.size(); ++i) px[i] = static_cast<uint8_t>(i * 7);
  write_gray8_png(p, 6, 5, px);
  expect_input_error([&] { read_depth_png(p, 1.0); }, p, "depth");
  try {
    read_depth_png(p, 1.0);
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("8-bit"), std::string::npos) << e.what();
  }
  // ...but it reads back as an 8-bit image.
  int w = 0, h = 0;
  EXPECT_EQ(read_gray8_png(p, &w, &h), px);
  EXPECT_EQ(w, 6);
  EXPECT_EQ(h, 5);
}

TEST(Png, MaskRoundTripIsExactAndSmall) {
  // A BOP-sized visible mask: one blob of 255 in zeros, as the generator
  // writes them (compressed for runs).
  TempDir tmp;
  const std::string p = tmp / "mask.png";
  const int W = 640, H = 480;
  std::vector<uint8_t> px(static_cast<size_t>(W) * H, 0);
  for (int v = 0; v < H; ++v)
    for (int u = 0; u < W; ++u)
      if ((u - 300) * (u - 300) + 2 * (v - 200) * (v - 200) < 90 * 90) px[static_cast<size_t>(v) * W + u] = 255;
  write_gray8_png(p, W, H, px);
  int w = 0, h = 0;
  EXPECT_EQ(read_gray8_png(p, &w, &h), px);
  EXPECT_EQ(w, W);
  EXPECT_EQ(h, H);
  EXPECT_LT(fs::file_size(p), 4000u);  // runs compress: 300 kB of pixels
}

TEST(Png, RunEncodedRowsReadBackExactly) {
  // The run encoder's cases: runs of every length around its limits (1-4
  // bytes, one back-reference of 258, 259-262 bytes, which leave one to four
  // after it), long runs, and values on both sides of the fixed Huffman
  // code's 143/144 split; read back through libpng and zlib.
  std::vector<uint8_t> row;
  const std::vector<int> lengths = {1, 2, 3, 4, 5, 10, 11, 257, 258, 259, 260, 261, 262, 515, 516, 517, 518, 1000};
  uint8_t value = 0;
  for (int len : lengths) {
    row.insert(row.end(), static_cast<size_t>(len), value);
    value = static_cast<uint8_t>(value * 37 + 101);  // every run a new value
  }
  for (int i = 0; i < 256; ++i) row.push_back(static_cast<uint8_t>(i));  // no runs at all
  TempDir tmp;
  for (int rows : {1, 3}) {
    const int W = static_cast<int>(row.size());
    std::vector<uint8_t> px;
    for (int r = 0; r < rows; ++r) px.insert(px.end(), row.begin(), row.end());
    const std::string p = tmp / ("runs" + std::to_string(rows) + ".png");
    write_gray8_png(p, W, rows, px);
    int w = 0, h = 0;
    EXPECT_EQ(read_gray8_png(p, &w, &h), px) << rows << " rows";
    EXPECT_EQ(w, W);
    EXPECT_EQ(h, rows);
  }
}

TEST(Png, RgbIsNotDepth) {
  TempDir tmp;
  const std::string p = tmp / "rgb.png";
  std::vector<uint8_t> rgb(4 * 3 * 3, 200);
  write_rgb8_png(p, 4, 3, rgb);
  expect_input_error([&] { read_depth_png(p, 1.0); }, p, "depth");
  const PngHeader h = read_png_header(p);
  EXPECT_EQ(h.channels, 3);
  EXPECT_EQ(h.bit_depth, 8);
}

TEST(Png, TruncatedFilesAreInputErrorsAtEveryLength) {
  TempDir tmp;
  const std::string good = tmp / "good.png";
  const DepthImage d = test_depth(1.0, 11);  // random values: poorly compressible
  write_depth_png(good, d, 1.0);
  const std::string bytes = slurp(good);
  ASSERT_GT(bytes.size(), 1000u);
  const std::string p = tmp / "cut.png";
  int checked = 0;
  for (size_t len = 0; len < bytes.size(); len += (len < 100 ? 1 : 97)) {
    {
      std::ofstream out(p, std::ios::binary | std::ios::trunc);
      out.write(bytes.data(), static_cast<std::streamsize>(len));
    }
    expect_input_error([&] { read_depth_png(p, 1.0); }, p, "depth");
    ++checked;
  }
  EXPECT_GT(checked, 100);
}

TEST(Png, CorruptedDataIsAnInputError) {
  TempDir tmp;
  const std::string good = tmp / "good.png";
  write_depth_png(good, test_depth(1.0, 5), 1.0);
  std::string bytes = slurp(good);
  // Flip bytes in the compressed stream (the CRC check or zlib catches it).
  for (size_t i = 60; i < bytes.size() - 20; i += 50) bytes[i] = static_cast<char>(bytes[i] ^ 0x5a);
  const std::string p = tmp / "bad.png";
  std::ofstream(p, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  expect_input_error([&] { read_depth_png(p, 1.0); }, p, "depth");
}

TEST(Png, NotAPngAndMissingFile) {
  TempDir tmp;
  const std::string p = tmp / "text.png";
  std::ofstream(p) << "this is not a PNG image, just some text that is long enough";
  expect_input_error([&] { read_depth_png(p, 1.0); }, p, "depth");
  const std::string missing = tmp / "missing.png";
  expect_input_error([&] { read_depth_png(missing, 1.0); }, missing, "depth");
  expect_input_error([&] { read_png_header(p); }, p, "image");
}

TEST(Png, AtomicWriteText) {
  TempDir tmp;
  const std::string p = tmp / "a.txt";
  atomic_write_text(p, "first");
  atomic_write_text(p, "second\n");
  EXPECT_EQ(slurp(p), "second\n");
  EXPECT_FALSE(fs::exists(p + ".tmp"));
  const std::string bad = tmp / "no_such_dir/a.txt";
  expect_input_error([&] { atomic_write_text(bad, "x"); }, bad, "output");
}
