// Real frames with ground truth, their GT renders and supporting planes
// (frames.h).
#include "simreal/frames.h"

#include <cmath>
#include <Eigen/Eigenvalues>
#include <filesystem>

#include "core/error.h"
#include "core/random.h"

namespace pb {

namespace fs = std::filesystem;

std::vector<GtFrame> list_gt_frames(const BopDataset& ds, const std::string& split, int max_images, int stride) {
  std::vector<GtFrame> out;
  int seen = 0;
  for (int sid : ds.scene_ids(split)) {
    const SceneInfo scene = ds.load_scene(split, sid);
    for (const auto& [iid, im] : scene.images) {
      if (im.gt.empty()) continue;
      if (!fs::exists(bop_depth_path(ds.scene_dir(split, sid), iid))) continue;
      if (seen++ % std::max(1, stride) != 0) continue;
      out.push_back(GtFrame{sid, im, {}});
      if (max_images > 0 && static_cast<int>(out.size()) >= max_images) return out;
    }
  }
  if (out.empty())
    throw InputError(ds.root(), split, "no image of this split has both a depth PNG and ground-truth poses");
  return out;
}

void load_gt_depth(const BopDataset& ds, const std::string& split, GtFrame& f) {
  f.depth = ds.load_depth(split, f.scene_id, f.info);
  if (f.info.K.width <= 0) f.info.K.width = f.depth.width, f.info.K.height = f.depth.height;
  for (float z : f.depth.z)
    if (std::isnan(z))
      throw InputError(bop_depth_path(ds.scene_dir(split, f.scene_id), f.info.im_id), "depth", "holds NaN depth");
}

const Mesh& ModelMeshes::get(int obj_id) {
  auto it = meshes_.find(obj_id);
  if (it != meshes_.end()) return *it->second;
  ds_.model_info(obj_id);  // InputError for an object models_info.json does not list
  auto m = std::make_unique<Mesh>(ds_.load_model(obj_id));
  if (m->empty()) throw InputError(ds_.model_path(obj_id), "faces", "the mesh has no triangles");
  return *meshes_.emplace(obj_id, std::move(m)).first->second;
}

DepthRenderer& RendererPool::get(const Intrinsics& K) {
  auto& r = renderers_[{K.width, K.height}];
  if (!r) {
    RenderSettings rs;
    rs.normals = true;
    r = std::make_unique<DepthRenderer>(K, rs);
  }
  r->set_intrinsics(K);
  return *r;
}

RenderOutput render_gt(RendererPool& pool, ModelMeshes& meshes, const ImageInfo& info, const Mesh* plane) {
  std::vector<RenderItem> items;
  for (size_t k = 0; k < info.gt.size(); ++k)
    items.push_back({&meshes.get(info.gt[k].obj_id), info.gt[k].T_cam_model, static_cast<int>(k)});
  if (plane) items.push_back({plane, Pose::identity(), kPlaneLabel});
  RenderOutput out = pool.get(info.K).render(items);
  if (plane)  // the objects' labels only; the plane is not an object
    for (int32_t& l : out.labels)
      if (l == kPlaneLabel) l = -1;
  return out;
}

SupportPlane fit_support_plane(const DepthImage& measured, const std::vector<int32_t>& gt_labels,
                               const Intrinsics& K, uint64_t seed, double inlier_mm) {
  // Every second pixel of every second row is plenty for a plane.
  std::vector<Vec3> pts;
  for (int v = 0; v < measured.height; v += 2)
    for (int u = 0; u < measured.width; u += 2) {
      const size_t p = static_cast<size_t>(v) * measured.width + u;
      if (measured.z[p] > 0 && gt_labels[p] < 0) pts.push_back(K.backproject(u, v, measured.z[p]));
    }
  SupportPlane best;
  best.candidates = static_cast<int>(pts.size());
  if (pts.size() < 3) return best;
  Rng rng(seed);
  const int n = static_cast<int>(pts.size());
  for (int it = 0; it < 500; ++it) {
    const Vec3& a = pts[rng.uniform_int(0, n - 1)];
    const Vec3& b = pts[rng.uniform_int(0, n - 1)];
    const Vec3& c = pts[rng.uniform_int(0, n - 1)];
    Vec3 nrm = (b - a).cross(c - a);
    if (nrm.norm() < 1e-6) continue;
    nrm.normalize();
    const double d = -nrm.dot(a);
    int cnt = 0;
    for (const Vec3& p : pts) cnt += std::abs(nrm.dot(p) + d) < inlier_mm;
    if (cnt > best.inliers) best.found = true, best.n = nrm, best.d = d, best.inliers = cnt;
  }
  if (!best.found) return best;
  // Least squares over the inliers.
  Vec3 c = Vec3::Zero();
  std::vector<Vec3> in;
  for (const Vec3& p : pts)
    if (std::abs(best.n.dot(p) + best.d) < inlier_mm) in.push_back(p), c += p;
  c /= static_cast<double>(in.size());
  Mat3 C = Mat3::Zero();
  for (const Vec3& p : in) C += (p - c) * (p - c).transpose();
  Eigen::SelfAdjointEigenSolver<Mat3> es(C);
  Vec3 nrm = es.eigenvectors().col(0).normalized();
  if (nrm.dot(c) > 0) nrm = -nrm;  // towards the camera (at the origin)
  best.n = nrm;
  best.d = -nrm.dot(c);
  return best;
}

Mesh support_plane_mesh(const SupportPlane& plane, const ImageInfo& info, double half_size_mm) {
  Vec3 c = Vec3::Zero();
  for (const auto& g : info.gt) c += g.T_cam_model.t;
  if (!info.gt.empty()) c /= static_cast<double>(info.gt.size());
  c -= (plane.n.dot(c) + plane.d) * plane.n;  // the foot on the plane
  const Vec3 a = plane.n.unitOrthogonal();
  const Vec3 b = plane.n.cross(a);
  Mesh m;
  for (int k = 0; k < 4; ++k) {
    const double sa = (k == 0 || k == 3) ? -1 : 1, sb = (k < 2) ? -1 : 1;
    m.vertices.push_back((c + half_size_mm * (sa * a + sb * b)).cast<float>());
  }
  m.faces.push_back({0, 1, 2});
  m.faces.push_back({0, 2, 3});
  return m;
}

TwinRender render_twin(RendererPool& pool, ModelMeshes& meshes, const GtFrame& f, uint64_t plane_seed,
                       double plane_inlier_mm) {
  TwinRender r;
  r.truth = render_gt(pool, meshes, f.info);
  r.plane = fit_support_plane(f.depth, r.truth.labels, f.info.K, plane_seed, plane_inlier_mm);
  Mesh plane_mesh;
  if (r.plane.found) plane_mesh = support_plane_mesh(r.plane, f.info);
  r.scene = render_gt(pool, meshes, f.info, r.plane.found ? &plane_mesh : nullptr);
  return r;
}

}  // namespace pb
