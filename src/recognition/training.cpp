// Training (offline): preprocess the training views the caller rendered,
// let the descriptor method describe them, and keep the result in memory and
// in the on-disk cache (cache.cpp).
#include <filesystem>

#include "core/file_lock.h"
#include "core/random.h"
#include "recognition/model.h"
#include "recognition/pipeline.h"
#include "recognition/preprocess/voxel_grid.h"
#include "recognition/registry.h"

namespace pb {

namespace {

constexpr int kMinViewPoints = 10;  // fewer points: the view is dropped
constexpr uint64_t kStreamTrainView = 21;  // derive_seed stream of a view's preprocessing

}  // namespace

void TrainedModel::derive_model_frame() {
  model_frame.clear();
  PointSet all;
  for (const auto& v : views) {
    const Pose T_model_cam = v.T_cam_model.inverse();
    const Eigen::Matrix3f R = T_model_cam.R.cast<float>();
    const Vec3f t = T_model_cam.t.cast<float>();
    PointSet m = v.cloud;
    for (auto& p : m.points) p = R * p + t;
    for (auto& n : m.normals) n = R * n;
    m.pixel.clear();  // pixels of a view image, meaningless once merged
    m.source_width = m.source_height = 0;
    all.points.insert(all.points.end(), m.points.begin(), m.points.end());
    if (m.has_normals()) all.normals.insert(all.normals.end(), m.normals.begin(), m.normals.end());
    if (m.curvature.size() == m.points.size())
      all.curvature.insert(all.curvature.end(), m.curvature.begin(), m.curvature.end());
    model_frame.push_back(std::move(m));
  }
  if (all.normals.size() != all.points.size()) all.normals.clear();
  if (all.curvature.size() != all.points.size()) all.curvature.clear();
  merged = voxel_downsample(all, {settings.preprocess.voxel_mm});
}

TrainedModelInfo trained_model_info(const TrainedModel& m) {
  TrainedModelInfo i;
  i.descriptor = m.descriptor;
  i.model_name = m.model_name;
  i.views = static_cast<int>(m.views.size());
  for (const auto& v : m.views) i.view_points += v.cloud.size();
  i.empty = m.method == nullptr;
  i.empty_reason = m.empty_reason;
  i.cache_file = m.cache_file;
  return i;
}

double training_views_diameter(const TrainingViews& input) {
  if (input.diameter_mm > 0) return input.diameter_mm;
  Eigen::AlignedBox3f box;
  for (const auto& v : input.views) {
    const Pose T_model_cam = v.T_cam_model.inverse();
    const Eigen::Matrix3f R = T_model_cam.R.cast<float>();
    const Vec3f t = T_model_cam.t.cast<float>();
    for (const Vec3f& p : v.cloud.points)
      if (p.allFinite() && p.z() > 0) box.extend(R * p + t);
  }
  return box.isEmpty() ? 0.0 : static_cast<double>(box.diagonal().norm());
}

std::shared_ptr<const TrainedModel> train_model(const TrainingViews& input, const RecognitionSettings& settings,
                                                const TrainOptions& opt, bool* from_cache) {
  if (from_cache) *from_cache = false;
  descriptor_entry(settings.descriptor);  // InputError for unknown names
  auto m = std::make_shared<TrainedModel>();
  m->model_name = input.model_name;
  m->diameter_mm = training_views_diameter(input);
  m->descriptor = settings.descriptor;
  if (input.views.empty()) {
    m->settings = settings;
    m->empty_reason = input.empty_reason.empty() ? "no training views of model '" + input.model_name + "'"
                                                 : input.empty_reason;
    return m;
  }
  const RecognitionSettings s = resolve_lengths(settings, m->diameter_mm);
  m->settings = s;

  const cache::Key key = cache::training_key(input, s);
  FileLock training_lock;
  if (!opt.cache_dir.empty()) {
    m->cache_file = cache::file_name(opt.cache_dir, input.model_name, s.descriptor, key);
    const auto from_file = [&] {
      if (!cache::read(m->cache_file, key, *m)) return false;
      m->derive_model_frame();
      if (from_cache) *from_cache = true;
      return true;
    };
    if (from_file()) return m;
    // Processes sharing the cache (workers, the shards of a sweep) train a
    // model once: the first takes FILE.lock and trains, the others wait for
    // it and then read what it wrote.
    std::error_code ec;
    std::filesystem::create_directories(std::filesystem::path(m->cache_file).parent_path(), ec);
    training_lock = FileLock::acquire(m->cache_file + ".lock");
    if (from_file()) return m;
  }

  for (size_t i = 0; i < input.views.size(); ++i) {
    ViewData v;
    v.cloud = preprocess_view(input.views[i].cloud, s.preprocess, derive_seed(s.seed, {kStreamTrainView, i}));
    v.T_cam_model = input.views[i].T_cam_model;
    if (v.cloud.size() >= static_cast<size_t>(kMinViewPoints)) m->views.push_back(std::move(v));
  }
  if (m->views.empty()) {
    m->empty_reason = "no training view of model '" + input.model_name + "' has " + std::to_string(kMinViewPoints) +
                      " points after preprocessing";
    return m;
  }
  m->method = make_method(s);
  m->method->train(m->views, s.seed);
  m->derive_model_frame();
  if (!m->cache_file.empty()) cache::write(m->cache_file, key, *m);
  return m;
}

}  // namespace pb
