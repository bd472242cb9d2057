// The recognition pipeline (THESIS.md "The system"): the method registry,
// training with its on-disk cache, and recognize(): preprocess the scene,
// let the descriptor method hypothesize, refine every hypothesis, count its
// inliers and keep the one with the most.
#include "recognition/pipeline.h"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <thread>

#include <unistd.h>

#include "core/random.h"
#include "core/timer.h"
#include "recognition/method.h"
#include "recognition/settings_internal.h"
#include "recognition/preprocess/internal.h"

namespace pb {

// ---------------------------------------------------------------- registry

std::unique_ptr<Method> make_method(const std::string& name) {
  static const std::map<std::string, std::function<std::unique_ptr<Method>()>> factories = {
      {"fpfh", make_fpfh_method}, {"shot", make_shot_method},       {"cvfh", make_cvfh_method},
      {"esf", make_esf_method},   {"cesf", make_cesf_method},       {"ourcvfh", make_ourcvfh_method},
      {"ppf", make_ppf_method},
  };
  const auto it = factories.find(name);
  if (it == factories.end()) check_descriptor_name(name, "", "descriptor");  // throws
  if (it == factories.end()) throw InputError("", "descriptor", "no method registered for '" + name + "'");
  return it->second();
}

// ---------------------------------------------------------------- model

class TrainedModel {
 public:
  std::string model_name;
  std::string descriptor;
  RecognitionSettings settings;          // the settings it was trained with
  std::unique_ptr<Method> method;        // null when there is nothing to recognize
  std::string empty_reason;              // why method is null
  std::vector<ViewData> views;           // preprocessed training views (view camera frame)
  std::vector<PointSet> model_frame;     // the same clouds mapped into the model frame
  PointSet merged;                       // every view in the model frame, voxelized (for view -1)
  std::string cache_file;                // where it was read from / written to ("" = none)

  const PointSet& model_cloud(int view) const {
    if (view < 0) return merged;
    if (static_cast<size_t>(view) >= model_frame.size())
      throw std::logic_error("recognition: hypothesis names view " + std::to_string(view) + " of " +
                             std::to_string(model_frame.size()));
    return model_frame[static_cast<size_t>(view)];
  }

  // The cloud verification counts inliers on (VerifySettings::inlier_model).
  const PointSet& verify_cloud(int view, const VerifySettings& v) const {
    return v.inlier_model == "merged" ? merged : model_cloud(view);
  }

  void derive_model_frame() {
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
    merged = detail::voxel_downsample(all, settings.preprocess.voxel_mm);
  }
};

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

// ---------------------------------------------------------------- cache

namespace {

constexpr char kMagic[8] = {'P', 'B', 'T', 'R', 'A', 'I', 'N', '\0'};
constexpr uint32_t kCacheVersion = 1;  // bump when ViewData or the file layout changes
constexpr int kMinViewPoints = 10;     // fewer points: the view is dropped
constexpr size_t kMinScenePoints = 3;

// Random streams of one call (derive_seed ids).
enum Stream : uint64_t { kStreamScene = 11, kStreamMethod = 12, kStreamRefine = 13, kStreamTrainView = 21 };

struct Fnv {
  uint64_t h = 1469598103934665603ull;
  void add(const void* data, size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < n; ++i) {
      h ^= p[i];
      h *= 1099511628211ull;
    }
  }
  void add(const std::string& s) {
    const uint64_t n = s.size();
    add(&n, sizeof n);
    add(s.data(), s.size());
  }
};

std::string training_key_text(const RecognitionSettings& s) {
  const auto j = detail::settings_json(s);
  nlohmann::ordered_json k;
  k["cache_version"] = kCacheVersion;
  for (const char* sec : {"descriptor", "views", "preprocess", "local", "global", "ppf", "seed"}) k[sec] = j[sec];
  k["local"].erase("threads");  // results are identical for any thread count
  return k.dump();
}

uint64_t training_key(const Mesh& mesh, const std::string& key_text) {
  Fnv f;
  f.add(key_text);
  const uint64_t nv = mesh.vertices.size(), nf = mesh.faces.size();
  f.add(&nv, sizeof nv);
  for (const auto& v : mesh.vertices) f.add(v.data(), 3 * sizeof(float));
  f.add(&nf, sizeof nf);
  for (const auto& t : mesh.faces) f.add(t.data(), 3 * sizeof(int));
  return f.h;
}

std::string sanitize(const std::string& name) {
  std::string o;
  for (char c : name) o += (std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_') ? c : '_';
  return o.empty() ? "model" : o.substr(0, 64);
}

// Binary writer / bounds-checked reader of the payload.
struct Writer {
  std::string buf;
  template <typename T>
  void pod(const T& v) {
    buf.append(reinterpret_cast<const char*>(&v), sizeof v);
  }
  void bytes(const std::string& s) {
    pod<uint64_t>(s.size());
    buf += s;
  }
  template <typename T>
  void vec(const std::vector<T>& v) {
    pod<uint64_t>(v.size());
    if (!v.empty()) buf.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
  }
};

struct Reader {
  const std::string& buf;
  size_t pos = 0;
  void need(size_t n) const {
    if (n > buf.size() - pos) throw std::runtime_error("truncated");
  }
  template <typename T>
  T pod() {
    need(sizeof(T));
    T v;
    std::memcpy(&v, buf.data() + pos, sizeof v);
    pos += sizeof v;
    return v;
  }
  std::string bytes() {
    const uint64_t n = pod<uint64_t>();
    need(n);
    std::string s = buf.substr(pos, n);
    pos += n;
    return s;
  }
  template <typename T>
  std::vector<T> vec() {
    const uint64_t n = pod<uint64_t>();
    if (n > (buf.size() - pos) / sizeof(T)) throw std::runtime_error("truncated");
    std::vector<T> v(n);
    if (n) std::memcpy(reinterpret_cast<char*>(v.data()), buf.data() + pos, n * sizeof(T));
    pos += n * sizeof(T);
    return v;
  }
};

void write_points(Writer& w, const std::vector<Vec3f>& pts) {
  std::vector<float> f;
  f.reserve(pts.size() * 3);
  for (const auto& p : pts) f.insert(f.end(), {p.x(), p.y(), p.z()});
  w.vec(f);
}

std::vector<Vec3f> read_points(Reader& r) {
  const std::vector<float> f = r.vec<float>();
  if (f.size() % 3) throw std::runtime_error("bad point array");
  std::vector<Vec3f> p(f.size() / 3);
  for (size_t i = 0; i < p.size(); ++i) p[i] = Vec3f(f[3 * i], f[3 * i + 1], f[3 * i + 2]);
  return p;
}

std::string serialize(const TrainedModel& m, const std::string& key_text) {
  Writer w;
  w.bytes(key_text);
  w.bytes(m.descriptor);
  w.pod<uint64_t>(m.views.size());
  for (const auto& v : m.views) {
    write_points(w, v.cloud.points);
    write_points(w, v.cloud.normals);
    w.vec(v.cloud.curvature);
    w.vec(v.cloud.pixel);
    w.pod<int32_t>(v.cloud.source_width);
    w.pod<int32_t>(v.cloud.source_height);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) w.pod<double>(v.T_cam_model.R(r, c));
    for (int r = 0; r < 3; ++r) w.pod<double>(v.T_cam_model.t[r]);
  }
  std::ostringstream ms(std::ios::binary);
  m.method->save(ms);
  w.bytes(ms.str());
  return w.buf;
}

// Fills views and method of `m` from a payload; throws on any mismatch.
void deserialize(TrainedModel& m, const std::string& payload, const std::string& key_text) {
  Reader r{payload};
  if (r.bytes() != key_text) throw std::runtime_error("key mismatch");
  if (r.bytes() != m.descriptor) throw std::runtime_error("descriptor mismatch");
  const uint64_t nv = r.pod<uint64_t>();
  if (nv > 100000) throw std::runtime_error("bad view count");
  std::vector<ViewData> views(nv);
  for (auto& v : views) {
    v.cloud.points = read_points(r);
    v.cloud.normals = read_points(r);
    v.cloud.curvature = r.vec<float>();
    v.cloud.pixel = r.vec<int>();
    v.cloud.source_width = r.pod<int32_t>();
    v.cloud.source_height = r.pod<int32_t>();
    const size_t n = v.cloud.points.size();
    if ((!v.cloud.normals.empty() && v.cloud.normals.size() != n) ||
        (!v.cloud.curvature.empty() && v.cloud.curvature.size() != n) ||
        (!v.cloud.pixel.empty() && v.cloud.pixel.size() != n))
      throw std::runtime_error("inconsistent view arrays");
    for (int a = 0; a < 3; ++a)
      for (int c = 0; c < 3; ++c) v.T_cam_model.R(a, c) = r.pod<double>();
    for (int a = 0; a < 3; ++a) v.T_cam_model.t[a] = r.pod<double>();
  }
  const std::string state = r.bytes();
  if (r.pos != payload.size()) throw std::runtime_error("trailing bytes");
  std::unique_ptr<Method> method = make_method(m.descriptor);
  std::istringstream is(state, std::ios::binary);
  method->load(is);
  // A state written by another version of the method rarely has exactly
  // the length this version reads: such a file is stale, not reusable.
  if (is.bad() || is.fail() || is.peek() != std::char_traits<char>::eof())
    throw std::runtime_error("method state unreadable or of another version");
  m.views = std::move(views);
  m.method = std::move(method);
}

bool read_cache(const std::string& path, uint64_t key, const std::string& key_text, TrainedModel& m) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  std::string file((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  try {
    Reader r{file};
    r.need(sizeof kMagic);
    if (std::memcmp(file.data(), kMagic, sizeof kMagic) != 0) return false;
    r.pos = sizeof kMagic;
    if (r.pod<uint32_t>() != kCacheVersion) return false;
    if (r.pod<uint64_t>() != key) return false;
    const uint64_t size = r.pod<uint64_t>(), sum = r.pod<uint64_t>();
    if (size != file.size() - r.pos) return false;
    Fnv f;
    f.add(file.data() + r.pos, size);
    if (f.h != sum) return false;
    deserialize(m, file.substr(r.pos), key_text);
    return true;
  } catch (const std::exception&) {
    // A corrupt or stale cache file is ignored (and rebuilt by the caller).
    m.views.clear();
    m.method.reset();
    return false;
  }
}

void write_cache(const std::string& path, uint64_t key, const std::string& payload) {
  std::string file(kMagic, sizeof kMagic);
  Writer w;
  w.pod<uint32_t>(kCacheVersion);
  w.pod<uint64_t>(key);
  w.pod<uint64_t>(payload.size());
  Fnv f;
  f.add(payload.data(), payload.size());
  w.pod<uint64_t>(f.h);
  file += w.buf;
  file += payload;
  static std::atomic<uint64_t> counter{0};
  const std::string tmp = path + ".tmp." + std::to_string(::getpid()) + "." +
                          std::to_string(std::hash<std::thread::id>()(std::this_thread::get_id())) + "." +
                          std::to_string(counter++);
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw InputError(path, "cache", "cannot write the training cache file");
    out.write(file.data(), static_cast<std::streamsize>(file.size()));
    out.close();
    if (!out) {
      std::remove(tmp.c_str());
      throw InputError(path, "cache", "cannot write the training cache file (disk full?)");
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::remove(tmp.c_str());
    throw InputError(path, "cache", "cannot rename the training cache file into place: " + ec.message());
  }
}

}  // namespace

std::shared_ptr<const TrainedModel> train_model(const Mesh& mesh, const RecognitionSettings& s,
                                                const TrainOptions& opt, bool* from_cache) {
  if (from_cache) *from_cache = false;
  check_descriptor_name(s.descriptor, "", "descriptor");
  auto m = std::make_shared<TrainedModel>();
  m->model_name = opt.model_name;
  m->descriptor = s.descriptor;
  m->settings = s;
  if (mesh.empty()) {
    m->empty_reason = "model '" + opt.model_name + "' has no triangles";
    return m;
  }
  if (!(mesh.bounds().diagonal().norm() > 0) || !mesh.bounds().diagonal().allFinite()) {
    m->empty_reason = "model '" + opt.model_name + "' is degenerate (zero or non-finite extent)";
    return m;
  }

  const std::string key_text = training_key_text(s);
  const uint64_t key = training_key(mesh, key_text);
  std::string path;
  if (!opt.cache_dir.empty()) {
    char hex[17];
    std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(key));
    path = opt.cache_dir + "/" + sanitize(opt.model_name) + "-" + s.descriptor + "-" + hex + ".bin";
    m->cache_file = path;
    if (read_cache(path, key, key_text, *m)) {
      m->derive_model_frame();
      if (from_cache) *from_cache = true;
      return m;
    }
  }

  const std::vector<TrainingView> rendered = render_training_views(mesh, s.views);
  for (size_t i = 0; i < rendered.size(); ++i) {
    ViewData v;
    v.cloud = preprocess_view(rendered[i].cloud, s.preprocess, derive_seed(s.seed, {kStreamTrainView, i}));
    v.T_cam_model = rendered[i].T_cam_model;
    if (v.cloud.size() >= static_cast<size_t>(kMinViewPoints)) m->views.push_back(std::move(v));
  }
  if (m->views.empty()) {
    m->empty_reason = "no training view of model '" + opt.model_name + "' has " + std::to_string(kMinViewPoints) +
                      " points after preprocessing";
    return m;
  }
  m->method = make_method(s.descriptor);
  m->method->train(m->views, s);
  m->derive_model_frame();

  if (!path.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(opt.cache_dir, ec);
    if (ec) throw InputError(opt.cache_dir, "cache", "cannot create the cache directory: " + ec.message());
    write_cache(path, key, serialize(*m, key_text));
  }
  return m;
}

// ---------------------------------------------------------------- recognize

namespace {

bool finite_pose(const Pose& p) { return p.R.allFinite() && p.t.allFinite(); }

}  // namespace

RecognitionResult recognize(const DepthImage& depth, const Intrinsics& K, const TrainedModel& model,
                            const RecognitionSettings& s) {
  RecognitionResult res;
  if (depth.width != K.width || depth.height != K.height ||
      depth.z.size() != static_cast<size_t>(depth.width) * static_cast<size_t>(depth.height))
    throw InputError("", "depth", "image is " + std::to_string(depth.width) + "x" + std::to_string(depth.height) +
                                      " but the intrinsics are for " + std::to_string(K.width) + "x" +
                                      std::to_string(K.height));
  if (s.descriptor != model.descriptor)
    throw InputError("", "descriptor", "the model was trained for '" + model.descriptor + "', the settings ask for '" +
                                           s.descriptor + "'");
  check_refinement_name(s.refinement, "", "refinement");
  if (!model.method) {
    res.message = "empty model: " + model.empty_reason;
    return res;
  }

  Timer timer;
  const OrganizedCloud cloud = OrganizedCloud::from_depth(depth, K);
  const PointSet scene = preprocess_scene(cloud, s.preprocess, derive_seed(s.seed, {kStreamScene}));
  res.times.preprocess = timer.seconds();
  if (scene.size() < kMinScenePoints) {
    res.message = "no scene points after filtering (" + std::to_string(cloud.valid_count()) + " valid pixels, " +
                  std::to_string(scene.size()) + " points after range cut, voxel grid, plane removal and normals)";
    return res;
  }

  std::vector<Hypothesis> hyps =
      model.method->hypothesize(scene, model.views, s, derive_seed(s.seed, {kStreamMethod}), res.times);
  hyps.erase(std::remove_if(hyps.begin(), hyps.end(), [](const Hypothesis& h) { return !finite_pose(h.T_cam_model); }),
             hyps.end());
  if (hyps.empty()) {
    res.message = "the " + model.descriptor + " method formed no hypothesis (" + std::to_string(scene.size()) +
                  " scene points)";
    return res;
  }

  // Hypotheses are refined and verified independently (one random stream
  // each, one output slot each), in parallel over OpenMP threads: the result
  // does not depend on the thread count.
  for (const auto& h : hyps) model.model_cloud(h.view);  // throws for a view index out of range
  const long nh = static_cast<long>(hyps.size());
  std::vector<std::exception_ptr> errors(hyps.size());
  timer.reset();
#pragma omp parallel for schedule(dynamic, 1)
  for (long i = 0; i < nh; ++i) {
    try {
      Hypothesis& h = hyps[static_cast<size_t>(i)];
      const RefineResult r = refine_pose(s.refinement, model.model_cloud(h.view), scene, h.T_cam_model, s.refine,
                                         derive_seed(s.seed, {kStreamRefine, static_cast<uint64_t>(i)}));
      if (finite_pose(r.T_cam_model)) {
        h.T_cam_model = r.T_cam_model;
        h.fitness = r.fitness;
        h.refined = s.refinement != "none";
      }
    } catch (...) {
      errors[static_cast<size_t>(i)] = std::current_exception();
    }
  }
  for (const auto& e : errors)
    if (e) std::rethrow_exception(e);  // the first failing hypothesis, whatever the thread count
  res.times.refine = timer.seconds();

  timer.reset();
  const PointIndex index(scene.points);
#pragma omp parallel for schedule(dynamic, 1)
  for (long i = 0; i < nh; ++i) {
    Hypothesis& h = hyps[static_cast<size_t>(i)];
    h.inliers = count_inliers(model.verify_cloud(h.view, s.verify).points, h.T_cam_model, index,
                              s.verify.inlier_threshold_mm);
  }
  // Most inliers first; ties by score, then view index, then the method's order.
  std::vector<size_t> order(hyps.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  auto score_of = [](const Hypothesis& h) { return std::isnan(h.score) ? -HUGE_VAL : h.score; };
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    const Hypothesis &x = hyps[a], &y = hyps[b];
    if (x.inliers != y.inliers) return x.inliers > y.inliers;
    if (score_of(x) != score_of(y)) return score_of(x) > score_of(y);
    if (x.view != y.view) return x.view < y.view;
    return a < b;
  });
  for (size_t i : order) res.hypotheses.push_back(hyps[i]);
  res.times.verify = timer.seconds();

  const Hypothesis& best = res.hypotheses.front();
  const size_t model_points = model.verify_cloud(best.view, s.verify).size();
  if (best.inliers < 1) {
    res.message = "no hypothesis has an inlier within " + std::to_string(s.verify.inlier_threshold_mm) + " mm";
    return res;
  }
  if (static_cast<double>(best.inliers) < s.verify.min_inlier_fraction * static_cast<double>(model_points)) {
    res.message = "the best hypothesis has " + std::to_string(best.inliers) + " inliers of " +
                  std::to_string(model_points) + " model points, below min_inlier_fraction " +
                  std::to_string(s.verify.min_inlier_fraction);
    return res;
  }
  res.status = "ok";
  res.T_cam_model = best.T_cam_model;
  res.score = best.score;
  res.inliers = best.inliers;
  return res;
}

}  // namespace pb

// ---------------------------------------------------------------- refine_from
// (refine_only.h) Registration alone: the thesis's Table 4.9 and Figure 4.12.

#include "recognition/refine_only.h"

namespace pb {

RecognitionResult refine_from(const DepthImage& depth, const Intrinsics& K, const TrainedModel& model,
                              const RecognitionSettings& s, const Pose& init) {
  RecognitionResult res;
  if (depth.width != K.width || depth.height != K.height ||
      depth.z.size() != static_cast<size_t>(depth.width) * static_cast<size_t>(depth.height))
    throw InputError("", "depth", "image size does not match the intrinsics");
  check_refinement_name(s.refinement, "", "refinement");
  if (model.views.empty()) {
    res.message = "empty model: " + model.empty_reason;
    return res;
  }
  Timer timer;
  const OrganizedCloud cloud = OrganizedCloud::from_depth(depth, K);
  const PointSet scene = preprocess_scene(cloud, s.preprocess, derive_seed(s.seed, {kStreamScene}));
  res.times.preprocess = timer.seconds();
  if (scene.size() < kMinScenePoints) {
    res.message = "no scene points after filtering";
    return res;
  }
  // The source is the training view seen from the direction closest to the
  // one `init` implies: the camera -> object ray expressed in the model frame.
  auto view_dir = [](const Pose& T_cam_model) -> Vec3 {
    return (T_cam_model.R.transpose() * T_cam_model.t.normalized()).normalized();
  };
  const Vec3 d = view_dir(init);
  int best_view = 0;
  double best_dot = -2;
  for (size_t v = 0; v < model.views.size(); ++v) {
    const double dot = view_dir(model.views[v].T_cam_model).dot(d);
    if (dot > best_dot) {
      best_dot = dot;
      best_view = static_cast<int>(v);
    }
  }
  Hypothesis h;
  h.T_cam_model = init;
  h.view = best_view;
  timer.reset();
  const RefineResult r = refine_pose(s.refinement, model.model_cloud(h.view), scene, init, s.refine,
                                     derive_seed(s.seed, {kStreamRefine, 0}));
  if (finite_pose(r.T_cam_model)) {
    h.T_cam_model = r.T_cam_model;
    h.fitness = r.fitness;
    h.refined = s.refinement != "none";
  }
  res.times.refine = timer.seconds();
  timer.reset();
  const PointIndex index(scene.points);
  h.inliers = count_inliers(model.verify_cloud(h.view, s.verify).points, h.T_cam_model, index,
                            s.verify.inlier_threshold_mm);
  res.times.verify = timer.seconds();
  res.hypotheses.push_back(h);
  res.status = "ok";
  res.T_cam_model = h.T_cam_model;
  res.inliers = h.inliers;
  return res;
}

}  // namespace pb
