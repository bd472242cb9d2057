// Offscreen depth rendering with OSMesa (fixed-function GL, 24-bit depth,
// linearized to millimetres). Camera: OpenCV convention, pixel centres at
// integer coordinates, row 0 at the top; depth exactly consistent with
// Intrinsics::backproject.
//
// How: the projection matrix maps OpenCV camera coordinates straight to clip
// space (x_ndc = (2 fx X/Z + 2 cx + 1)/W - 1, y flipped, w = Z), so pixel
// (u, v) is sampled at its centre. Each triangle is drawn flat-shaded with a
// unique 32-bit id in the RGBA colour buffer; the depth test decides
// visibility. Per pixel the id gives the item (label) and the face; with
// exact_depth the depth is the intersection of the pixel's ray with that
// face's plane in double precision (no depth-buffer quantization at any
// distance), otherwise the 24-bit buffer linearized by
// z = 2fn / ((f+n) - z_ndc (f-n)). Normals come from the same face plane.
#pragma once

#include <cstdint>
#include <memory>
#include <stdexcept>
#include <vector>

#include "core/types.h"

namespace pb {

struct RenderItem {
  const Mesh* mesh = nullptr;  // not owned
  Pose T_cam_model;
  int label = 0;               // written to RenderOutput::labels where visible
};

struct RenderOutput {
  DepthImage depth;             // mm, 0 where nothing was drawn
  std::vector<int32_t> labels;  // per pixel the label of the visible item, -1 none
  // Per pixel surface normal in the camera frame (unit, oriented towards the
  // camera: n . ray < 0), zero where empty; filled only when requested (used
  // by sensor noise models).
  std::vector<Vec3f> normals;
};

struct RenderSettings {
  double near_mm = 50.0;     // near clipping plane
  double far_mm = 20000.0;   // far clipping plane
  bool normals = false;      // also compute per pixel normals
  // Depth from the visible face's plane intersected with the pixel ray
  // (double precision, exact at any distance); false: the linearized 24-bit
  // depth buffer (quantization grows with z^2 / near_mm).
  bool exact_depth = true;
};

// One renderer owns one OSMesa context and buffers; use one per thread.
class DepthRenderer {
 public:
  DepthRenderer(const Intrinsics& K, RenderSettings settings = {});
  ~DepthRenderer();
  DepthRenderer(const DepthRenderer&) = delete;
  DepthRenderer& operator=(const DepthRenderer&) = delete;

  RenderOutput render(const std::vector<RenderItem>& items);
  // The labels of render(items) alone, the same values: no depth read back,
  // no face planes (silhouettes and visibility counts need nothing else).
  // overlap = false promises that no two items cover a common pixel (one
  // item, or items apart in the image): then every pixel's label is that of
  // whichever item covers it, and no depth test is needed to find it.
  std::vector<int32_t> render_labels(const std::vector<RenderItem>& items, bool overlap = true);
  const Intrinsics& intrinsics() const { return K_; }
  // Changes the intrinsics of the next renders; the image size must stay the
  // same (buffers are sized at construction). Lets one context render tiles
  // of a larger virtual image by shifting the principal point (scenes: the
  // full silhouette of an object crossing the image border).
  void set_intrinsics(const Intrinsics& K) {
    if (K.width != K_.width || K.height != K_.height)
      throw std::invalid_argument("DepthRenderer::set_intrinsics: the image size must not change");
    K_ = K;
  }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  // Rasterizes items into the colour (face ids) and depth buffers; returns
  // the global face id bases (see renderer.cpp).
  std::vector<uint64_t> rasterize(const std::vector<RenderItem>& items, bool depth_test, bool read_depth);
  Intrinsics K_;
  RenderSettings settings_;
};

}  // namespace pb
