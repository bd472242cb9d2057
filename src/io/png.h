// PNG images: 16-bit depth in and out, 8-bit gray in and out, 8-bit RGB
// out. Read through libpng, written by io/png_write.h.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/types.h"

namespace pb {

// Reads a single-channel 16-bit PNG as depth in mm: z = value * depth_scale.
// Throws InputError(path, "depth", ...) if missing, not a PNG, or not a
// 16-bit single-channel image (e.g. an 8-bit or RGB PNG).
DepthImage read_depth_png(const std::string& path, double depth_scale);

// Writes depth as uint16 value = round(z / depth_scale); 0 stays 0. Throws
// InputError if a value does not fit in 16 bits.
void write_depth_png(const std::string& path, const DepthImage& depth, double depth_scale);

// 8-bit images (masks, previews, overlays).
// Reads an 8-bit gray PNG (e.g. a BOP mask); InputError(path, "image", ...)
// for any other format.
std::vector<uint8_t> read_gray8_png(const std::string& path, int* width, int* height);
// Written for long runs of one value (masks): larger for noisy content.
void write_gray8_png(const std::string& path, int width, int height, const std::vector<uint8_t>& px);
void write_rgb8_png(const std::string& path, int width, int height, const std::vector<uint8_t>& rgb);
// The same PNG's bytes, in memory (e.g. to embed in an HTML page).
std::string encode_rgb8_png(int width, int height, const std::vector<uint8_t>& rgb);

// Size and format of a PNG from its header (any PNG); InputError(path,
// "image", ...) if missing or not a PNG.
struct PngHeader {
  int width = 0, height = 0;
  int bit_depth = 0;  // bits per channel
  int channels = 0;
};
PngHeader read_png_header(const std::string& path);

// Writes bytes to `path + ".tmp"` and renames it into place (see below).
// InputError(path, "output", ...) if the file cannot be written.
void atomic_write_bytes(const std::string& path, const void* data, size_t size);

// Writes the file to `path + ".tmp"` and renames it into place, so a reader
// never sees a half-written file. Used by every writer of posebench.
void atomic_write_text(const std::string& path, const std::string& text);

}  // namespace pb
