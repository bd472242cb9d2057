#include "scenes/import_clouds.h"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <sstream>

#include "core/error.h"
#include "io/bop.h"
#include "io/folder.h"
#include "io/mesh_io.h"
#include "io/png.h"
#include "io/validate.h"
#include "models/registry.h"

namespace pb {

namespace fs = std::filesystem;

namespace {

Intrinsics parse_intrinsics_text(const std::string& text, int w, int h) {
  std::vector<double> v;
  std::stringstream ss(text);
  for (std::string tok; std::getline(ss, tok, ',');) {
    char* end = nullptr;
    const double x = std::strtod(tok.c_str(), &end);
    if (tok.empty() || *end != '\0') throw InputError("", "intrinsics", "'" + tok + "' is not a number");
    v.push_back(x);
  }
  if (v.size() != 4 && v.size() != 6)
    throw InputError("", "intrinsics", "expected fx,fy,cx,cy or fx,fy,cx,cy,width,height");
  Intrinsics K;
  K.fx = v[0], K.fy = v[1], K.cx = v[2], K.cy = v[3];
  K.width = v.size() == 6 ? static_cast<int>(v[4]) : w;
  K.height = v.size() == 6 ? static_cast<int>(v[5]) : h;
  if (K.width <= 0 || K.height <= 0 || K.width > 20000 || K.height > 20000 ||
      (v.size() == 6 && (v[4] != K.width || v[5] != K.height)))
    throw InputError("", "intrinsics", "an unorganized cloud needs the image size as whole numbers: "
                                       "fx,fy,cx,cy,width,height");
  validate_intrinsics(K, "", "intrinsics");
  return K;
}

}  // namespace

CloudScene cloud_scene(const PointCloudFile& pc, const std::string& path, const std::string& intrinsics,
                       const std::string& camera) {
  CloudScene s;
  if (!intrinsics.empty() && !camera.empty())
    throw InputError("", "intrinsics", "give intrinsics or a camera.json, not both");
  if (!intrinsics.empty()) {
    s.K = parse_intrinsics_text(intrinsics, pc.organized() ? pc.width : 0, pc.organized() ? pc.height : 0);
    s.source = "given";
  } else if (!camera.empty()) {
    s.K = read_camera_json(camera);
    s.source = "camera.json";
  } else if (pc.organized()) {
    s.K = fit_intrinsics(pc, path);
    s.source = "fitted";
  } else {
    s.K = virtual_camera(pc, path);
    s.source = "virtual";
  }
  const bool grid = pc.organized() && s.K.width == pc.width && s.K.height == pc.height;
  s.depth = grid ? organized_depth(pc) : project_cloud(pc, s.K);
  if (s.depth.valid_count() == 0) throw InputError(path, "points", "no point projects into the image through the intrinsics");
  return s;
}

ImportCloudsSummary import_clouds(const ImportCloudsSettings& st, const std::string& out) {
  if (st.clouds.empty()) throw InputError("", "clouds", "no cloud given");
  if (st.objects.empty()) throw InputError("", "object", "no object given");
  const fs::path dir(out);
  if (fs::exists(dir) && !fs::is_empty(dir) && !fs::exists(dir / "posebench_clouds.json"))
    throw InputError(out, "--out", "exists and is not a dataset of imported clouds; remove it or choose another");
  const ModelRegistry reg = st.registry.empty() ? ModelRegistry::load_default() : ModelRegistry::load(st.registry);
  ImportCloudsSummary sum;
  std::vector<CloudScene> scenes;
  double max_z = 0;
  for (const auto& path : st.clouds) {
    scenes.push_back(cloud_scene(read_cloud(path, st.units), path, st.intrinsics, st.camera));
    for (float z : scenes.back().depth.z) max_z = std::max(max_z, static_cast<double>(z));
    sum.intrinsics_source.push_back(scenes.back().source);
  }
  sum.depth_scale = max_z < 6500 ? 0.1 : 1.0;
  // Filled under OUT.partial and moved into place at the end (io/folder.h):
  // an interrupted import leaves no folder that looks complete.
  write_folder_atomically(out, "cannot write the dataset: ", [&](const fs::path& tmp) {
    fs::create_directories(tmp / "models");
    std::map<int, ModelInfo> infos;
    for (const auto& name : st.objects) {
      const ModelSpec& spec = reg.spec(name);
      const Mesh mesh = reg.load_model(name);
      write_ply((tmp / "models" / ("obj_" + bop_id(spec.obj_id) + ".ply")).string(), mesh);
      ModelInfo info = reg.info(name, mesh);
      info.obj_id = spec.obj_id;
      info.name = name;
      infos[spec.obj_id] = info;
    }
    write_models_info((tmp / "models" / "models_info.json").string(), infos);
    SceneInfo scene;
    scene.scene_id = 1;
    const std::string scene_dir = (tmp / "test" / bop_id(1)).string();
    fs::create_directories(fs::path(scene_dir) / "depth");
    nlohmann::json trace = nlohmann::json::array();
    for (size_t i = 0; i < scenes.size(); ++i) {
      ImageInfo im;
      im.im_id = static_cast<int>(i);
      im.K = scenes[i].K;
      im.depth_scale = sum.depth_scale;
      write_depth_png(bop_depth_path(scene_dir, im.im_id), scenes[i].depth, sum.depth_scale);
      scene.images[im.im_id] = im;
      trace.push_back({{"im_id", im.im_id}, {"cloud", fs::absolute(st.clouds[i]).string()},
                       {"intrinsics", sum.intrinsics_source[i]}});
    }
    write_scene_json(scene_dir, scene);
    // camera.json gives readers the image size: only when every image has the
    // first one's (otherwise each size comes from its depth PNG).
    bool one_size = true;
    for (const auto& c : scenes) one_size = one_size && c.K.width == scenes[0].K.width && c.K.height == scenes[0].K.height;
    if (one_size) write_camera_json((tmp / "camera.json").string(), scenes[0].K, sum.depth_scale);
    atomic_write_text((tmp / "posebench_clouds.json").string(), nlohmann::json({{"images", trace}}).dump(2) + "\n");
  });
  sum.images = static_cast<int>(scenes.size());
  return sum;
}

}  // namespace pb
