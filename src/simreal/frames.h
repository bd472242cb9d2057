// Real frames with ground truth, as the sim-to-real tools read them: the
// images of a BOP dataset that have a depth PNG and GT poses, the GT
// objects rendered at their poses, and the supporting plane fitted to the
// measured depth.
#pragma once

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/types.h"
#include "io/bop.h"
#include "render/renderer.h"

namespace pb {

struct GtFrame {
  int scene_id = 0;
  ImageInfo info;     // K, depth_scale, gt, gt_info
  DepthImage depth;   // measured, mm (0 = no depth)
};

// Every image of the split with a depth PNG and at least one GT pose, in
// order (its scene and image info, each scene's JSON read once): every
// stride-th of them, at most max_images (0 = all). InputError naming the
// dataset when there is none.
std::vector<GtFrame> list_gt_frames(const BopDataset& ds, const std::string& split, int max_images = 0,
                                    int stride = 1);
// Reads one of them's depth; InputError naming the PNG when its size is not
// the image's (camera.json) or it holds NaN.
void load_gt_depth(const BopDataset& ds, const std::string& split, GtFrame& f);

// The dataset's meshes, each loaded once (mm, model frame).
class ModelMeshes {
 public:
  explicit ModelMeshes(const BopDataset& ds) : ds_(ds) {}
  const Mesh& get(int obj_id);

 private:
  const BopDataset& ds_;
  std::map<int, std::unique_ptr<Mesh>> meshes_;
};

// One renderer per image size.
class RendererPool {
 public:
  DepthRenderer& get(const Intrinsics& K);

 private:
  std::map<std::pair<int, int>, std::unique_ptr<DepthRenderer>> renderers_;
};

// The label the supporting plane gets in a scene render.
inline constexpr int kPlaneLabel = 1 << 20;

// The GT objects at their poses (labels = index into info.gt), with
// normals; with `plane`, the plane too (label kPlaneLabel).
RenderOutput render_gt(RendererPool& pool, ModelMeshes& meshes, const ImageInfo& info, const Mesh* plane = nullptr);

// The supporting plane n . x + d = 0 (camera frame, mm; n towards the
// camera), fitted by RANSAC to the measured points that no GT object covers.
struct SupportPlane {
  bool found = false;
  Vec3 n = Vec3::UnitZ();
  double d = 0;
  int inliers = 0;      // measured points within inlier_mm
  int candidates = 0;   // measured points it was fitted to
};
SupportPlane fit_support_plane(const DepthImage& measured, const std::vector<int32_t>& gt_labels,
                               const Intrinsics& K, uint64_t seed, double inlier_mm = 8.0);
// A square of the plane, `half_size_mm` from the foot of the GT objects'
// centroid (so wider than any view at table distances), as two triangles
// facing the camera.
Mesh support_plane_mesh(const SupportPlane& plane, const ImageInfo& info, double half_size_mm = 4000);

// What a twin of a real frame is rendered from: the GT objects alone (the
// truth the statistics compare with) and the GT objects on the supporting
// plane fitted to the measured depth (RANSAC seeded with plane_seed; the
// scene the noise model degrades).
struct TwinRender {
  RenderOutput truth, scene;
  SupportPlane plane;
};
TwinRender render_twin(RendererPool& pool, ModelMeshes& meshes, const GtFrame& f, uint64_t plane_seed,
                       double plane_inlier_mm = 8.0);

}  // namespace pb
