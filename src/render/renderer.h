// Offscreen depth rendering with OSMesa (fixed-function GL, 24-bit depth,
// linearized to millimetres). Camera: OpenCV convention, pixel centres at
// integer coordinates, row 0 at the top; depth exactly consistent with
// Intrinsics::backproject.
#pragma once

#include <cstdint>
#include <memory>
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
  // Per pixel surface normal in the camera frame (unit), zero where empty;
  // filled only when requested (used by sensor noise models).
  std::vector<Vec3f> normals;
};

struct RenderSettings {
  double near_mm = 50.0;     // near clipping plane
  double far_mm = 20000.0;   // far clipping plane
  bool normals = false;      // also compute per pixel normals
};

// One renderer owns one OSMesa context and buffers; use one per thread.
class DepthRenderer {
 public:
  DepthRenderer(const Intrinsics& K, RenderSettings settings = {});
  ~DepthRenderer();
  DepthRenderer(const DepthRenderer&) = delete;
  DepthRenderer& operator=(const DepthRenderer&) = delete;

  RenderOutput render(const std::vector<RenderItem>& items);
  const Intrinsics& intrinsics() const { return K_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  Intrinsics K_;
  RenderSettings settings_;
};

}  // namespace pb
