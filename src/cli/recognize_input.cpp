#include "cli/recognize_input.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/error.h"
#include "io/cloud.h"
#include "io/mesh_io.h"
#include "io/ply_check.h"
#include "models/registry.h"
#include "scenes/import_clouds.h"
#include "scenes/views.h"

namespace pbcli {

namespace {

// The vertex and face counts a PLY header declares (-1: none declared), by
// io's header parser (ply_check.h) on the file's first MiB; false for a
// file that does not start as a PLY. InputError for a broken header.
bool ply_element_counts(const std::string& path, long* vertices, long* faces) {
  std::ifstream in(path, std::ios::binary);
  std::string head(1 << 20, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<size_t>(in.gcount()));
  if (head.rfind("ply", 0) != 0) return false;
  const auto counts = pb::ply_element_counts(path, head, "model");
  const auto count = [&](const char* name) {
    const auto it = counts.find(name);
    return it == counts.end() ? -1L : static_cast<long>(it->second);
  };
  *vertices = count("vertex");
  *faces = count("face");
  return true;
}

// A PLY whose header declares zero vertices or zero faces (assimp refuses
// such files: an empty model, not an input error).
bool ply_declares_no_geometry(const std::string& path) {
  long v = 0, f = 0;
  return ply_element_counts(path, &v, &f) && (v == 0 || f == 0);
}

// A point-cloud model file: .pcd, or a .ply that declares no faces.
bool is_cloud_model(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  long v = 0, f = 0;
  return ext == ".pcd" || (ext == ".ply" && ply_element_counts(path, &v, &f) && f <= 0);
}

RecognizeScene dataset_scene(RecognizeSource& o) {
  const pb::BopDataset ds(o.dataset_dir);
  if (o.scene < 0 || o.image < 0) throw pb::InputError("", "--scene", "a dataset image needs --scene and --image");
  if (o.split.empty()) {
    const auto sp = ds.splits();
    if (sp.empty()) throw pb::InputError(o.dataset_dir, "split", "the dataset has no split folder with scenes");
    o.split = std::find(sp.begin(), sp.end(), "test") != sp.end() ? "test" : sp.front();
  }
  const pb::SceneInfo sc = ds.load_scene(o.split, o.scene);
  const auto it = sc.images.find(o.image);
  if (it == sc.images.end())
    throw pb::InputError(o.dataset_dir + "/" + o.split + "/" + pb::bop_id(o.scene) + "/scene_camera.json", "image",
                         "no image " + std::to_string(o.image) + " in scene " + std::to_string(o.scene));
  RecognizeScene s;
  s.im = it->second;
  s.depth = ds.load_depth(o.split, o.scene, s.im);
  if (s.im.K.width <= 0 || s.im.K.height <= 0) {
    s.im.K.width = s.depth.width;
    s.im.K.height = s.depth.height;
  }
  const pb::ImageInfo& first = sc.images.begin()->second;
  s.first_depth = first.im_id == s.im.im_id ? s.depth : ds.load_depth(o.split, o.scene, first);
  s.first_K = first.K;
  s.source = {{"dataset", o.dataset_dir}, {"split", o.split}, {"scene", o.scene}, {"image", o.image}};
  s.description = o.split + " scene " + std::to_string(o.scene) + " image " + std::to_string(o.image);
  return s;
}

RecognizeScene cloud_scene(const RecognizeSource& o) {
  const pb::PointCloudFile pc = pb::read_cloud(o.cloud, pb::parse_cloud_units(o.units, "--units"));
  pb::CloudScene cs = pb::cloud_scene(pc, o.cloud, o.intrinsics, o.camera);
  RecognizeScene s;
  s.depth = std::move(cs.depth);
  s.im.K = cs.K;
  const pb::Intrinsics& K = s.im.K;
  s.first_depth = s.depth;
  s.first_K = K;
  const std::string how = cs.source == "fitted"    ? "fitted to the organized cloud"
                          : cs.source == "virtual" ? "virtual (the cloud's angular extent in 640x480)"
                                                   : cs.source;
  s.source = {{"cloud", o.cloud},
              {"units", pc.metres ? "m" : "mm"},
              {"organized", pc.organized()},
              {"intrinsics", {{"fx", K.fx}, {"fy", K.fy}, {"cx", K.cx}, {"cy", K.cy}, {"width", K.width},
                              {"height", K.height}, {"source", how}}}};
  std::ostringstream d;
  d << "cloud " << o.cloud << " (" << (pc.organized() ? "organized " : "unorganized, ") << pc.width << "x" << pc.height
    << (pc.metres ? ", metres" : ", mm") << "; intrinsics " << how << ": fx " << K.fx << " fy " << K.fy << " cx "
    << K.cx << " cy " << K.cy << ", " << K.width << "x" << K.height << ")";
  s.description = d.str();
  return s;
}

}  // namespace

RecognizeScene load_recognize_scene(RecognizeSource& src) {
  if (src.cloud.empty() == src.dataset_dir.empty())
    throw pb::InputError("", src.cloud.empty() ? "--dataset" : "--cloud",
                         "give either --dataset with --scene and --image, or --cloud");
  return src.cloud.empty() ? dataset_scene(src) : cloud_scene(src);
}

RecognizeObject load_recognize_object(const RecognizeSource& src) {
  RecognizeObject obj;
  if (src.object.empty() == src.model.empty())
    throw pb::InputError("", "--object", "give either --object (an id or name) or --model (a mesh file in mm)");
  if (!src.model.empty()) {
    obj.name = std::filesystem::path(src.model).stem().string();
    obj.info.name = obj.name;
    if (!is_cloud_model(src.model)) {
      obj.mesh = pb::load_mesh(src.model);
      return obj;
    }
    for (const pb::Vec3f& p : pb::read_cloud(src.model, pb::parse_cloud_units(src.model_units, "--model-units")).points)
      if (p.allFinite()) obj.cloud.push_back(p);
    const pb::Pose T = pb::cloud_model_pose(obj.cloud);
    for (const pb::Vec3f& p : obj.cloud) obj.mesh.vertices.push_back((p.cast<double>() - T.t).cast<float>());
    return obj;
  }
  if (src.dataset_dir.empty()) {  // the model registry
    const pb::ModelRegistry reg = pb::ModelRegistry::load_default();
    const pb::ModelSpec& spec = reg.spec(src.object);
    obj.mesh = reg.load_model(src.object);
    obj.obj_id = spec.obj_id;
    obj.name = spec.name;
    obj.info.obj_id = spec.obj_id;
    obj.info.name = spec.name;
    obj.info.symmetries_discrete = spec.symmetries_discrete;
    obj.info.symmetries_continuous = spec.symmetries_continuous;
    return obj;
  }
  const pb::BopDataset ds(src.dataset_dir);
  obj.obj_id = ds.resolve_object(src.object);
  obj.info = ds.model_info(obj.obj_id);
  try {
    obj.mesh = ds.load_model(obj.obj_id);
  } catch (const pb::InputError&) {
    // A well-formed PLY without vertices or faces is an empty model (the
    // result says so); a missing or broken file stays an input error.
    if (!ply_declares_no_geometry(ds.model_path(obj.obj_id))) throw;
  }
  obj.name = obj.info.name.empty() ? "obj_" + pb::bop_id(obj.obj_id) : obj.info.name;
  return obj;
}

}  // namespace pbcli
