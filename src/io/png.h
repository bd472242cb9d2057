// PNG images through libpng: 16-bit depth in and out, 8-bit RGB out.
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
void write_gray8_png(const std::string& path, int width, int height, const std::vector<uint8_t>& px);
void write_rgb8_png(const std::string& path, int width, int height, const std::vector<uint8_t>& rgb);

// Writes the file to `path + ".tmp"` and renames it into place, so a reader
// never sees a half-written file. Used by every writer of posebench.
void atomic_write_text(const std::string& path, const std::string& text);

}  // namespace pb
