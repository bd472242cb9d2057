// generate_dataset: a whole scene set in the BOP layout (scenes/generator.h),
// and the depth preview.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <functional>
#include <mutex>
#include <nlohmann/json.hpp>
#include <thread>

#include "core/error.h"
#include "core/timer.h"
#include "io/folder.h"
#include "io/mesh_io.h"
#include "io/png.h"
#include "scenes/generator.h"

namespace pb {

namespace fs = std::filesystem;

namespace {

// An existing `out` may only be replaced if it is a posebench scene set.
void check_out_dir(const std::string& out_dir) {
  const fs::path out(out_dir);
  if (out.empty() || out.filename() == "." || out.filename() == "..")
    throw InputError(out_dir, "--out", "not a usable output directory name");
  if (fs::exists(out)) {
    if (!fs::is_directory(out)) throw InputError(out_dir, "--out", "exists and is not a directory");
    if (!fs::is_empty(out) && !fs::exists(out / "posebench_scene.json"))
      throw InputError(out_dir, "--out", "exists and is not a posebench scene set; remove it or choose another");
  }
}

// models/ (PLY and models_info.json) and camera.json.
void write_models_and_camera(const fs::path& tmp, const SceneGenerator& gen) {
  const SceneSettings& s = gen.settings();
  fs::create_directories(tmp / "models");
  std::map<int, ModelInfo> infos;
  for (const auto& m : gen.models()) {
    write_ply((tmp / "models" / ("obj_" + bop_id(m.obj_id) + ".ply")).string(), m.mesh);
    infos[m.obj_id] = m.info;
  }
  write_models_info((tmp / "models" / "models_info.json").string(), infos);
  write_camera_json((tmp / "camera.json").string(), dataset_intrinsics(s), s.depth_scale);
}

// One image's result kept for the scene files and the trace.
struct Done {
  ImageInfo info;
  nlohmann::ordered_json trace;
  double target_visib = 0;
};

// Depth PNG, visible masks and (first image) the depth preview.
void write_image_files(const fs::path& tmp, const fs::path& scene_dir, const SceneSettings& s, int im,
                       const GeneratedImage& img) {
  const std::string iid = bop_id(im);
  write_depth_png((scene_dir / "depth" / (iid + ".png")).string(), img.depth, s.depth_scale);
  const int W = img.depth.width, H = img.depth.height;
  if (s.masks)
    for (size_t k = 0; k < img.info.gt.size(); ++k) {
      // Label k's pixels all lie in its visible box (gt_info_of).
      std::vector<uint8_t> m(static_cast<size_t>(W) * H, 0);
      const auto& box = img.info.gt_info[k].bbox_visib;  // x, y, w, h; w = 0 when none is visible
      for (int v = box[1]; v < box[1] + box[3]; ++v)
        for (int u = box[0]; u < box[0] + box[2]; ++u) {
          const size_t p = static_cast<size_t>(v) * W + u;
          if (img.labels[p] == static_cast<int>(k)) m[p] = 255;
        }
      write_gray8_png((scene_dir / "mask_visib" / (iid + "_" + bop_id(static_cast<int>(k)) + ".png")).string(), W,
                      H, m);
    }
  if (im == 0) write_rgb8_png((tmp / "depth_preview.png").string(), W, H, depth_preview_rgb(img.depth, &s.sensor.K));
}

// The image's entry of posebench_scene.json "images".
nlohmann::ordered_json image_trace(int im, const GeneratedImage& img, double target_visib) {
  nlohmann::ordered_json t;
  t["im_id"] = im;
  t["attempts"] = img.attempts;
  t["camera_distance_mm"] = img.camera_distance_mm;
  t["camera_elevation_deg"] = img.camera_elevation_deg;
  t["camera_azimuth_deg"] = img.camera_azimuth_deg;
  std::vector<double> Tw;
  const Mat4 M = img.T_world_cam.matrix();
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) Tw.push_back(M(r, c));
  t["T_world_cam"] = Tw;
  t["occluded"] = img.occluded;
  t["occluder_height_mm"] = img.occluder_height_mm;
  t["objects"] = img.names;
  t["target_visib_fract"] = target_visib;
  return t;
}

// Runs make_image(generator, im) for every image on `workers` threads, each
// with its own generator (`gen` on this thread, clones on the others).
// Images are independent (own seeds): any number of workers gives the same
// files. The first error stops the work and is rethrown.
void run_workers(SceneGenerator& gen, int images, int workers, void (*progress)(int done, int total),
                 const std::function<void(SceneGenerator&, int)>& make_image) {
  std::atomic<int> next{0};
  std::mutex mu;
  std::exception_ptr error;
  int finished = 0;
  auto work = [&](SceneGenerator* g) {
    try {
      std::unique_ptr<SceneGenerator> own;
      if (!g) {
        own = gen.clone();
        g = own.get();
      }
      for (;;) {
        {
          std::lock_guard<std::mutex> lock(mu);
          if (error) return;
        }
        const int im = next++;
        if (im >= images) return;
        make_image(*g, im);
        std::lock_guard<std::mutex> lock(mu);
        ++finished;
        if (progress) progress(finished, images);
      }
    } catch (...) {
      std::lock_guard<std::mutex> lock(mu);
      if (!error) error = std::current_exception();
    }
  };
  std::vector<std::thread> pool;
  for (int w = 1; w < workers; ++w) pool.emplace_back(work, nullptr);
  work(&gen);
  for (auto& t : pool) t.join();
  if (error) std::rethrow_exception(error);
}

// scene_*.json, test_targets_bop19.json and posebench_scene.json (written last: its presence marks a
// complete scene set); fills the summary's counts.
void write_scene_files(const fs::path& tmp, const fs::path& scene_dir, const SceneGenerator& gen,
                       std::vector<Done>& done, GenerateSummary& sum) {
  const SceneSettings& s = gen.settings();
  SceneInfo scene;
  scene.scene_id = s.scene_id;
  nlohmann::ordered_json trace = nlohmann::ordered_json::array();
  double visib_sum = 0, visib_min = 1;
  for (int im = 0; im < s.images; ++im) {
    visib_sum += done[im].target_visib;
    visib_min = std::min(visib_min, done[im].target_visib);
    sum.objects += static_cast<int>(done[im].info.gt.size());
    trace.push_back(std::move(done[im].trace));
    scene.images[im] = std::move(done[im].info);
  }
  write_scene_json(scene_dir.string(), scene);
  // Every object visible enough, BOP 2019's rule: `object: all` runs them.
  write_test_targets((tmp / "test_targets_bop19.json").string(), scene_test_targets(scene));

  sum.images = s.images;
  sum.mean_target_visib = visib_sum / s.images;
  sum.min_target_visib = visib_min;
  nlohmann::ordered_json j;
  j["format"] = "posebench scene set";
  j["settings"] = nlohmann::ordered_json::parse(scene_settings_json(s));
  nlohmann::ordered_json jm = nlohmann::ordered_json::array();
  for (const auto& m : gen.models())
    jm.push_back({{"obj_id", m.obj_id}, {"name", m.name}, {"scale", m.scale}, {"diameter", m.info.diameter}});
  j["models"] = jm;
  j["summary"] = {{"images", sum.images}, {"objects", sum.objects},
                  {"mean_target_visib_fract", sum.mean_target_visib},
                  {"min_target_visib_fract", sum.min_target_visib}};
  j["images"] = trace;
  atomic_write_text((tmp / "posebench_scene.json").string(), j.dump(2) + "\n");
}

}  // namespace

std::vector<uint8_t> depth_preview_rgb(const DepthImage& depth, const Intrinsics* K) {
  std::vector<float> valid;
  for (float z : depth.z)
    if (z > 0.f) valid.push_back(z);
  float lo = 0, hi = 1;
  if (!valid.empty()) {
    const size_t a = valid.size() * 2 / 100, b = std::min(valid.size() - 1, valid.size() * 98 / 100);
    std::nth_element(valid.begin(), valid.begin() + a, valid.end());
    lo = valid[a];
    std::nth_element(valid.begin(), valid.begin() + b, valid.end());
    hi = valid[b];
    if (hi <= lo) hi = lo + 1;
  }
  // Warm (near) to cool (far), shaded by the surface normal (light at the
  // camera) so object outlines stand out.
  static const float keys[5][3] = {{165, 0, 38}, {244, 109, 67}, {254, 224, 144}, {116, 173, 209}, {49, 54, 149}};
  const int W = depth.width, H = depth.height;
  std::vector<uint8_t> rgb(depth.z.size() * 3, 0);
  for (int v = 0; v < H; ++v)
    for (int u = 0; u < W; ++u) {
      const size_t i = static_cast<size_t>(v) * W + u;
      const float z = depth.z[i];
      if (!(z > 0.f)) continue;
      float shade = 1.f;
      if (K && u > 0 && v > 0 && u + 1 < W && v + 1 < H) {
        const float zl = depth.at(u - 1, v), zr = depth.at(u + 1, v), zu = depth.at(u, v - 1), zd = depth.at(u, v + 1);
        const float jump = 30.f;
        if (zl > 0 && zr > 0 && zu > 0 && zd > 0 && std::abs(zr - zl) < 2 * jump && std::abs(zd - zu) < 2 * jump) {
          const Vec3 dx = K->backproject(u + 1, v, zr) - K->backproject(u - 1, v, zl);
          const Vec3 dy = K->backproject(u, v + 1, zd) - K->backproject(u, v - 1, zu);
          Vec3 n = dy.cross(dx);
          const Vec3 ray = K->backproject(u, v, z).normalized();
          if (n.norm() > 0) {
            n.normalize();
            shade = static_cast<float>(0.3 + 0.7 * std::abs(n.dot(ray)));
          }
        } else {
          shade = 0.3f;  // depth edge
        }
      }
      const float t = std::clamp((z - lo) / (hi - lo), 0.f, 1.f) * 4.f;
      const int k = std::min(3, static_cast<int>(t));
      const float f = t - k;
      for (int c = 0; c < 3; ++c)
        rgb[3 * i + c] = static_cast<uint8_t>(std::lround(shade * (keys[k][c] * (1 - f) + keys[k + 1][c] * f)));
    }
  return rgb;
}

GenerateSummary generate_dataset(const SceneSettings& settings, const std::string& out_dir,
                                 void (*progress)(int done, int total), int threads) {
  Timer timer;
  check_out_dir(out_dir);
  // Loads models (InputError for bad ones) before anything is written.
  SceneGenerator gen(settings);
  const SceneSettings& s = gen.settings();
  GenerateSummary sum;
  write_folder_atomically(out_dir, "cannot write the scene set: ", [&](const fs::path& tmp) {
    write_models_and_camera(tmp, gen);
    const fs::path scene_dir = tmp / "test" / bop_id(s.scene_id);
    fs::create_directories(scene_dir / "depth");
    if (s.masks) fs::create_directories(scene_dir / "mask_visib");
    std::vector<Done> done(s.images);
    run_workers(gen, s.images, std::max(1, std::min(threads, s.images)), progress, [&](SceneGenerator& g, int im) {
      GeneratedImage img = g.generate(im);
      write_image_files(tmp, scene_dir, s, im, img);
      Done& d = done[im];
      d.target_visib = img.info.gt_info.empty() ? 0.0 : img.info.gt_info[0].visib_fract;
      d.trace = image_trace(im, img, d.target_visib);
      d.info = std::move(img.info);
    });
    write_scene_files(tmp, scene_dir, gen, done, sum);
  });
  const fs::path out(out_dir);
  sum.out_dir = out.string();
  sum.preview_png = (out / "depth_preview.png").string();
  sum.seconds = timer.seconds();
  return sum;
}

}  // namespace pb
