// BOP dataset reading and writing (../shared/reference/bop_datasets_format.md).
// JSON keys are image/object ids as strings ("0", "1", ...), matrices are
// row-major flat lists, translations in mm, depth_png * depth_scale = mm.
// Numbers are written by nlohmann-json with the shortest representation that
// reads back to the same double, so poses round-trip bit for bit.
#include "io/bop.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "core/error.h"
#include "io/bop_internal.h"
#include "io/png.h"
#include "io/validate.h"

namespace fs = std::filesystem;

namespace pb {

namespace {

using json = nlohmann::json;
using ojson = nlohmann::ordered_json;
using bop_detail::is_digits;
using bop_detail::join_path;

json read_json(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "", std::string("cannot open JSON file: ") + std::strerror(errno));
  std::stringstream ss;
  ss << in.rdbuf();
  try {
    return json::parse(ss.str());
  } catch (const json::exception& e) {  // parse_error, and out_of_range for a number like 1e99999
    throw InputError(path, "", std::string("malformed JSON: ") + e.what());
  }
}

// A JSON value with the file it came from and its key path, for messages.
struct JRef {
  const json& j;
  const std::string& file;
  std::string path;

  JRef key(const std::string& k) const {
    if (!j.is_object()) throw InputError(file, path, "expected a JSON object");
    auto it = j.find(k);
    if (it == j.end()) throw InputError(file, join(k), "missing key");
    return JRef{*it, file, join(k)};
  }
  bool has(const std::string& k) const { return j.is_object() && j.contains(k) && !j.at(k).is_null(); }
  JRef at(size_t i) const { return JRef{j.at(i), file, path + "[" + std::to_string(i) + "]"}; }
  std::string join(const std::string& k) const { return path.empty() ? k : path + "." + k; }

  double num() const {
    if (!j.is_number()) throw InputError(file, path, "expected a number");
    const double v = j.get<double>();
    if (!std::isfinite(v)) throw InputError(file, path, "not a finite number");
    return v;
  }
  int integer() const {
    if (!j.is_number_integer() && !(j.is_number_float() && std::floor(j.get<double>()) == j.get<double>()))
      throw InputError(file, path, "expected an integer");
    const double v = j.get<double>();
    if (std::abs(v) > 2147483647.0) throw InputError(file, path, "integer out of range");
    return static_cast<int>(v);
  }
  const json& array(size_t n) const {
    if (!j.is_array()) throw InputError(file, path, "expected a list");
    if (n && j.size() != n)
      throw InputError(file, path, "expected " + std::to_string(n) + " numbers, got " + std::to_string(j.size()));
    return j;
  }
  std::vector<double> nums(size_t n) const {
    array(n);
    std::vector<double> v;
    for (size_t i = 0; i < j.size(); ++i) v.push_back(at(i).num());
    return v;
  }
  std::array<int, 4> int4() const {
    array(4);
    return {at(0).integer(), at(1).integer(), at(2).integer(), at(3).integer()};
  }
};

int parse_id(const std::string& key, const std::string& file) {
  if (key.empty() || key.size() > 9 || !std::all_of(key.begin(), key.end(), [](char c) { return c >= '0' && c <= '9'; }))
    throw InputError(file, key, "expected an integer id as key");
  return std::stoi(key);
}

Mat3 mat3_rowmajor(const std::vector<double>& v) {
  Mat3 M;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) M(r, c) = v[3 * r + c];
  return M;
}
ojson rowmajor(const Mat3& M) {
  ojson a = ojson::array();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) a.push_back(M(r, c));
  return a;
}
ojson rowmajor(const Mat4& M) {
  ojson a = ojson::array();
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) a.push_back(M(r, c));
  return a;
}
ojson vec3(const Vec3& v) { return ojson::array({v.x(), v.y(), v.z()}); }
ojson int4(const std::array<int, 4>& a) { return ojson::array({a[0], a[1], a[2], a[3]}); }

void write_json(const std::string& path, const ojson& j) {
  // One top-level entry per line (as bop_toolkit writes them): readable,
  // diffable, compact.
  std::string out = "{\n";
  bool first = true;
  for (auto it = j.begin(); it != j.end(); ++it) {
    if (!first) out += ",\n";
    first = false;
    out += "  " + ojson(it.key()).dump() + ": " + it.value().dump();
  }
  out += "\n}\n";
  atomic_write_text(path, out);
}

// SCENE_DIR/<file>, if present: a JSON object keyed by image id (each in
// scene_camera.json) whose values are lists; calls fn(image, list).
template <class Fn>
void read_image_lists(const std::string& path, SceneInfo& scene, Fn fn) {
  if (!fs::exists(path)) return;
  const json root = read_json(path);
  if (!root.is_object()) throw InputError(path, "", "expected a JSON object keyed by image id");
  for (auto it = root.begin(); it != root.end(); ++it) {
    const int id = parse_id(it.key(), path);
    auto im = scene.images.find(id);
    if (im == scene.images.end()) throw InputError(path, it.key(), "image id not in scene_camera.json");
    const JRef list{it.value(), path, it.key()};
    list.array(0);
    fn(im->second, list);
  }
}

}  // namespace

std::string bop_id(int id) {
  char buf[16];
  std::snprintf(buf, sizeof(buf), "%06d", id);
  return buf;
}

std::string bop_depth_path(const std::string& scene_dir, int im_id) {
  return join_path(join_path(scene_dir, "depth"), bop_id(im_id) + ".png");
}

// ---------------------------------------------------------------- test targets

std::vector<TestTarget> read_test_targets(const std::string& path) {
  const json root = read_json(path);
  if (!root.is_array()) throw InputError(path, "", "expected a JSON list of {scene_id, im_id, obj_id, inst_count}");
  const JRef list{root, path, ""};
  std::vector<TestTarget> out;
  for (size_t i = 0; i < root.size(); ++i) {
    const JRef e = list.at(i);
    if (!e.j.is_object()) throw InputError(path, e.path, "expected a JSON object");
    const auto field = [&](const char* k, int min) {
      const int v = e.key(k).integer();
      if (v < min) throw InputError(path, e.join(k), "must be " + std::to_string(min) + " or more");
      return v;
    };
    out.push_back({field("scene_id", 0), field("im_id", 0), field("obj_id", 0), field("inst_count", 1)});
  }
  return out;
}

std::vector<TestTarget> scene_test_targets(const SceneInfo& scene, double min_visib_fract) {
  std::vector<TestTarget> out;
  for (const auto& [id, im] : scene.images) {
    if (im.gt_info.size() != im.gt.size()) continue;
    std::map<int, int> count;  // obj_id -> instances visible enough
    for (size_t k = 0; k < im.gt.size(); ++k)
      if (im.gt_info[k].visib_fract >= min_visib_fract) ++count[im.gt[k].obj_id];
    for (const auto& [obj, n] : count) out.push_back({scene.scene_id, id, obj, n});
  }
  return out;
}

void write_test_targets(const std::string& path, const std::vector<TestTarget>& targets) {
  // One entry per line, as bop_toolkit writes them.
  std::string out = "[";
  for (size_t i = 0; i < targets.size(); ++i) {
    const TestTarget& t = targets[i];
    const ojson e = {{"im_id", t.im_id}, {"inst_count", t.inst_count}, {"obj_id", t.obj_id}, {"scene_id", t.scene_id}};
    out += (i == 0 ? "\n  " : ",\n  ") + e.dump();
  }
  out += targets.empty() ? "]\n" : "\n]\n";
  atomic_write_text(path, out);
}

// ---------------------------------------------------------------- models_info

std::map<int, ModelInfo> read_models_info(const std::string& path) {
  const json root = read_json(path);
  if (!root.is_object()) throw InputError(path, "", "expected a JSON object keyed by object id");
  std::map<int, ModelInfo> out;
  for (auto it = root.begin(); it != root.end(); ++it) {
    ModelInfo m;
    m.obj_id = parse_id(it.key(), path);
    const JRef e{it.value(), path, it.key()};
    if (!e.j.is_object()) throw InputError(path, it.key(), "expected a JSON object");
    m.diameter = e.key("diameter").num();
    if (!(m.diameter > 0)) throw InputError(path, e.join("diameter"), "must be positive");
    m.min = Vec3(e.key("min_x").num(), e.key("min_y").num(), e.key("min_z").num());
    m.size = Vec3(e.key("size_x").num(), e.key("size_y").num(), e.key("size_z").num());
    for (int k = 0; k < 3; ++k)
      if (m.size[k] < 0) throw InputError(path, e.join(std::string("size_") + "xyz"[k]), "must not be negative");
    if (e.has("name")) {
      if (!e.j.at("name").is_string()) throw InputError(path, e.join("name"), "expected a string");
      m.name = e.j.at("name").get<std::string>();
    }
    if (e.has("symmetries_discrete")) {
      const JRef s = e.key("symmetries_discrete");
      s.array(0);
      for (size_t i = 0; i < s.j.size(); ++i) {
        const auto v = s.at(i).nums(16);
        Mat4 T;
        for (int r = 0; r < 4; ++r)
          for (int c = 0; c < 4; ++c) T(r, c) = v[4 * r + c];
        const std::string field = s.path + "[" + std::to_string(i) + "]";
        if (T(3, 0) != 0 || T(3, 1) != 0 || T(3, 2) != 0 || T(3, 3) != 1)
          throw InputError(path, field, "the last row of a symmetry transform must be 0 0 0 1");
        validate_rotation(T.topLeftCorner<3, 3>(), kSymmetryRotationTolerance, path, field);
        m.symmetries_discrete.push_back(T);
      }
    }
    if (e.has("symmetries_continuous")) {
      const JRef s = e.key("symmetries_continuous");
      s.array(0);
      for (size_t i = 0; i < s.j.size(); ++i) {
        const JRef c = s.at(i);
        const auto a = c.key("axis").nums(3);
        const auto o = c.key("offset").nums(3);
        ContinuousSymmetry cs;
        cs.axis = Vec3(a[0], a[1], a[2]);
        cs.offset = Vec3(o[0], o[1], o[2]);
        if (cs.axis.norm() == 0) throw InputError(path, c.join("axis"), "axis must not be zero");
        m.symmetries_continuous.push_back(cs);
      }
    }
    out[m.obj_id] = m;
  }
  return out;
}

void write_models_info(const std::string& path, const std::map<int, ModelInfo>& models) {
  ojson root = ojson::object();
  for (const auto& [id, m] : models) {
    ojson e = ojson::object();
    e["diameter"] = m.diameter;
    e["min_x"] = m.min.x();
    e["min_y"] = m.min.y();
    e["min_z"] = m.min.z();
    e["size_x"] = m.size.x();
    e["size_y"] = m.size.y();
    e["size_z"] = m.size.z();
    if (!m.symmetries_discrete.empty()) {
      ojson a = ojson::array();
      for (const auto& T : m.symmetries_discrete) a.push_back(rowmajor(T));
      e["symmetries_discrete"] = a;
    }
    if (!m.symmetries_continuous.empty()) {
      ojson a = ojson::array();
      for (const auto& c : m.symmetries_continuous) {
        ojson s = ojson::object();
        s["axis"] = vec3(c.axis);
        s["offset"] = vec3(c.offset);
        a.push_back(s);
      }
      e["symmetries_continuous"] = a;
    }
    if (!m.name.empty()) e["name"] = m.name;  // posebench extension
    root[std::to_string(id)] = e;
  }
  write_json(path, root);
}

// ---------------------------------------------------------------- camera.json

void write_camera_json(const std::string& path, const Intrinsics& K, double depth_scale) {
  ojson j = ojson::object();
  j["cx"] = K.cx;
  j["cy"] = K.cy;
  j["depth_scale"] = depth_scale;
  j["fx"] = K.fx;
  j["fy"] = K.fy;
  j["height"] = K.height;
  j["width"] = K.width;
  write_json(path, j);
}

Intrinsics read_camera_json(const std::string& path, double* depth_scale) {
  const json j = read_json(path);
  const JRef r{j, path, ""};
  if (!j.is_object()) throw InputError(path, "", "expected a JSON object");
  Intrinsics K;
  K.cx = r.key("cx").num();
  K.cy = r.key("cy").num();
  K.fx = r.key("fx").num();
  K.fy = r.key("fy").num();
  K.width = r.key("width").integer();
  K.height = r.key("height").integer();
  if (K.width <= 0) throw InputError(path, "width", "must be positive");
  if (K.height <= 0) throw InputError(path, "height", "must be positive");
  validate_intrinsics(K, path, "");
  if (depth_scale) {
    *depth_scale = r.has("depth_scale") ? r.key("depth_scale").num() : 1.0;
    if (!(*depth_scale > 0)) throw InputError(path, "depth_scale", "must be positive");
  }
  return K;
}

// ---------------------------------------------------------------- scene json

void write_scene_json(const std::string& scene_dir, const SceneInfo& scene) {
  std::error_code ec;
  fs::create_directories(scene_dir, ec);
  if (ec) throw InputError(scene_dir, "output", "cannot create the folder: " + ec.message());
  ojson cam = ojson::object(), gt = ojson::object(), info = ojson::object();
  bool any_info = false;
  for (const auto& [id, im] : scene.images) {
    if (!im.gt_info.empty() && im.gt_info.size() != im.gt.size())
      throw std::invalid_argument("write_scene_json: image " + std::to_string(id) +
                                  " has gt_info not parallel to gt");
    any_info = any_info || !im.gt_info.empty();
  }
  for (const auto& [id, im] : scene.images) {
    const std::string key = std::to_string(id);
    ojson c = ojson::object();
    c["cam_K"] = rowmajor(im.K.K());
    c["depth_scale"] = im.depth_scale;
    cam[key] = c;
    ojson g = ojson::array();
    for (const auto& o : im.gt) {
      ojson e = ojson::object();
      e["cam_R_m2c"] = rowmajor(o.T_cam_model.R);
      e["cam_t_m2c"] = vec3(o.T_cam_model.t);
      e["obj_id"] = o.obj_id;
      g.push_back(e);
    }
    gt[key] = g;
    if (any_info) {
      ojson a = ojson::array();
      for (const auto& gi : im.gt_info) {
        ojson e = ojson::object();
        e["bbox_obj"] = int4(gi.bbox_obj);
        e["bbox_visib"] = int4(gi.bbox_visib);
        e["px_count_all"] = gi.px_count_all;
        e["px_count_valid"] = gi.px_count_valid;
        e["px_count_visib"] = gi.px_count_visib;
        e["visib_fract"] = gi.visib_fract;
        a.push_back(e);
      }
      info[key] = a;
    }
  }
  write_json(join_path(scene_dir, "scene_camera.json"), cam);
  write_json(join_path(scene_dir, "scene_gt.json"), gt);
  if (any_info) write_json(join_path(scene_dir, "scene_gt_info.json"), info);
}

SceneInfo read_scene_json(const std::string& scene_dir) {
  SceneInfo scene;
  const std::string dirname = fs::path(scene_dir).lexically_normal().filename().string();
  const std::string base = dirname.empty() ? fs::path(scene_dir).parent_path().filename().string() : dirname;
  scene.scene_id = is_digits(base) && base.size() <= 9 ? std::stoi(base) : 0;

  const std::string cam_path = join_path(scene_dir, "scene_camera.json");
  const json cam = read_json(cam_path);
  if (!cam.is_object()) throw InputError(cam_path, "", "expected a JSON object keyed by image id");
  for (auto it = cam.begin(); it != cam.end(); ++it) {
    ImageInfo im;
    im.im_id = parse_id(it.key(), cam_path);
    const JRef e{it.value(), cam_path, it.key()};
    const Mat3 K = mat3_rowmajor(e.key("cam_K").nums(9));
    validate_camera_matrix(K, 0, 0, cam_path, e.join("cam_K"));  // the image size is checked with the dataset's
    im.K = Intrinsics::from_K(K, 0, 0);
    im.depth_scale = e.has("depth_scale") ? e.key("depth_scale").num() : 1.0;
    if (!(im.depth_scale > 0)) throw InputError(cam_path, e.join("depth_scale"), "must be positive");
    scene.images[im.im_id] = im;
  }

  read_image_lists(join_path(scene_dir, "scene_gt.json"), scene, [](ImageInfo& im, const JRef& list) {
    for (size_t i = 0; i < list.j.size(); ++i) {
      const JRef e = list.at(i);
      GtObject o;
      o.obj_id = e.key("obj_id").integer();
      o.T_cam_model.R = mat3_rowmajor(e.key("cam_R_m2c").nums(9));
      validate_rotation(o.T_cam_model.R, kPoseRotationTolerance, list.file, e.join("cam_R_m2c"));
      const auto t = e.key("cam_t_m2c").nums(3);
      o.T_cam_model.t = Vec3(t[0], t[1], t[2]);
      im.gt.push_back(o);
    }
  });
  read_image_lists(join_path(scene_dir, "scene_gt_info.json"), scene, [](ImageInfo& im, const JRef& list) {
    if (list.j.size() != im.gt.size())
      throw InputError(list.file, list.path,
                       std::to_string(list.j.size()) + " entries but scene_gt.json has " +
                           std::to_string(im.gt.size()));
    // Every field is meta information (bop_toolkit's calc_gt_info.py) and
    // optional here: converted datasets often lack some. A missing box stays
    // (-1, -1, 0, 0), a missing count -1; a missing visib_fract is
    // px_count_visib / px_count_all when both are given, else unknown (NaN).
    for (size_t i = 0; i < list.j.size(); ++i) {
      const JRef e = list.at(i);
      if (!e.j.is_object()) throw InputError(list.file, e.path, "expected a JSON object");
      GtInfo gi;
      const auto count = [&](const char* k) { return e.has(k) ? e.key(k).integer() : -1; };
      if (e.has("bbox_obj")) gi.bbox_obj = e.key("bbox_obj").int4();
      if (e.has("bbox_visib")) gi.bbox_visib = e.key("bbox_visib").int4();
      gi.px_count_all = count("px_count_all");
      gi.px_count_valid = count("px_count_valid");
      gi.px_count_visib = count("px_count_visib");
      if (e.has("visib_fract"))
        gi.visib_fract = e.key("visib_fract").num();
      else if (gi.px_count_all > 0 && gi.px_count_visib >= 0)
        gi.visib_fract = static_cast<double>(gi.px_count_visib) / gi.px_count_all;
      else
        gi.visib_fract = std::nan("");
      im.gt_info.push_back(gi);
    }
  });
  return scene;
}

}  // namespace pb
