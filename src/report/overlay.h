// Depth overlays: a depth image colour-mapped with the model drawn at an
// estimated pose (tinted green, bright outline) and the ground truth
// outlined in magenta; what `recognize --overlay` writes and the report's
// failure gallery shows.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/types.h"

namespace pb {

struct RgbImage {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;  // row-major, 3 bytes per pixel
};

// The scene depth colour-mapped (near = blue, far = red, between the 1st and
// 99th percentile; no depth = black), `est` (if given) and `gt` (if given)
// drawn over it through K (K's size must be the depth's).
RgbImage depth_overlay(const DepthImage& depth, const Intrinsics& K, const Mesh& mesh, const Pose* est,
                       const Pose* gt);

// depth_overlay written as a PNG.
void write_overlay(const std::string& path, const DepthImage& depth, const Intrinsics& K, const Mesh& mesh,
                   const Pose* est, const Pose* gt);

}  // namespace pb
