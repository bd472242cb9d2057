// BopDataset: read access to a BOP dataset root (io/bop.h).
#include <algorithm>
#include <filesystem>

#include "core/error.h"
#include "io/bop.h"
#include "io/bop_internal.h"
#include "io/mesh_io.h"
#include "io/png.h"
#include "io/validate.h"

namespace fs = std::filesystem;

namespace pb {

using bop_detail::is_digits;
using bop_detail::join_path;

// ---------------------------------------------------------------- BopDataset

BopDataset::BopDataset(std::string root) : root_(std::move(root)) {
  std::error_code ec;
  if (!fs::is_directory(root_, ec))
    throw InputError(root_, "dataset", "not a BOP dataset: no such folder");
  const std::string info = join_path(join_path(root_, "models"), "models_info.json");
  if (!fs::exists(info, ec))
    throw InputError(root_, "dataset", "not a BOP dataset: models/models_info.json is missing");
  if (splits().empty())
    throw InputError(root_, "dataset",
                     "not a BOP dataset: no split folder with scenes (e.g. test/000001/scene_camera.json)");
  models_ = read_models_info(info);
  const std::string cam = join_path(root_, "camera.json");
  if (fs::exists(cam, ec)) {
    double s = 1.0;
    camera_ = read_camera_json(cam, &s);
    camera_depth_scale_ = s;
  }
}

std::vector<std::string> BopDataset::splits() const {
  std::vector<std::string> out;
  std::error_code ec;
  for (const auto& d : fs::directory_iterator(root_, ec)) {
    if (!d.is_directory()) continue;
    const std::string name = d.path().filename().string();
    if (name.rfind("models", 0) == 0) continue;
    if (!scene_ids(name).empty()) out.push_back(name);
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<int> BopDataset::scene_ids(const std::string& split) const {
  std::vector<int> ids;
  std::error_code ec;
  const fs::path dir = fs::path(root_) / split;
  if (!fs::is_directory(dir, ec)) return ids;
  for (const auto& d : fs::directory_iterator(dir, ec)) {
    const std::string name = d.path().filename().string();
    if (d.is_directory() && is_digits(name) && name.size() <= 9 && fs::exists(d.path() / "scene_camera.json"))
      ids.push_back(std::stoi(name));
  }
  std::sort(ids.begin(), ids.end());
  return ids;
}

std::string BopDataset::scene_dir(const std::string& split, int scene_id) const {
  return join_path(join_path(root_, split), bop_id(scene_id));
}

SceneInfo BopDataset::load_scene(const std::string& split, int scene_id) const {
  const std::string dir = scene_dir(split, scene_id);
  if (!fs::exists(join_path(dir, "scene_camera.json")))
    throw InputError(dir, "scene", "no scene " + std::to_string(scene_id) + " in split '" + split + "'");
  SceneInfo s = read_scene_json(dir);
  s.scene_id = scene_id;
  for (auto& [id, im] : s.images) {
    if (camera_) {
      im.K.width = camera_->width;
      im.K.height = camera_->height;
    } else {
      const std::string p = bop_depth_path(dir, id);
      if (fs::exists(p)) {
        const PngHeader h = read_png_header(p);
        im.K.width = h.width;
        im.K.height = h.height;
      }
    }
    validate_intrinsics(im.K, join_path(dir, "scene_camera.json"), std::to_string(id) + ".cam_K");
  }
  return s;
}

DepthImage BopDataset::load_depth(const std::string& split, int scene_id, const ImageInfo& im) const {
  const std::string p = bop_depth_path(scene_dir(split, scene_id), im.im_id);
  DepthImage d = read_depth_png(p, im.depth_scale);
  if ((im.K.width > 0 && d.width != im.K.width) || (im.K.height > 0 && d.height != im.K.height))
    throw InputError(p, "depth",
                     "image is " + std::to_string(d.width) + "x" + std::to_string(d.height) + " but the camera is " +
                         std::to_string(im.K.width) + "x" + std::to_string(im.K.height));
  return d;
}

const ModelInfo& BopDataset::model_info(int obj_id) const {
  auto it = models_.find(obj_id);
  if (it == models_.end())
    throw InputError(join_path(join_path(root_, "models"), "models_info.json"), std::to_string(obj_id),
                     "unknown object id " + std::to_string(obj_id));
  return it->second;
}

int BopDataset::resolve_object(const std::string& s) const {
  const std::string info = join_path(join_path(root_, "models"), "models_info.json");
  std::string digits;
  if (is_digits(s)) digits = s;
  else if (s.rfind("obj_", 0) == 0 && is_digits(s.substr(4))) digits = s.substr(4);
  if (!digits.empty() && digits.size() <= 9) {
    const int id = std::stoi(digits);
    if (models_.count(id)) return id;
  }
  for (const auto& [id, m] : models_)
    if (!m.name.empty() && m.name == s) return id;
  std::string known;
  for (const auto& [id, m] : models_) {
    if (!known.empty()) known += ", ";
    known += std::to_string(id);
    if (!m.name.empty()) known += " (" + m.name + ")";
  }
  throw InputError(info, "object", "unknown object '" + s + "' (known: " + known + ")");
}

std::string BopDataset::model_path(int obj_id) const {
  return join_path(join_path(root_, "models"), "obj_" + bop_id(obj_id) + ".ply");
}

Mesh BopDataset::load_model(int obj_id) const {
  model_info(obj_id);  // unknown id -> InputError
  return load_mesh(model_path(obj_id));
}

}  // namespace pb
