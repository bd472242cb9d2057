#include "eval/score.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <set>
#include <utility>

#include "core/error.h"
#include "eval/bop_csv.h"
#include "eval/symmetry.h"
#include "io/bop.h"
#include "render/renderer.h"

namespace pb {

namespace {

namespace fs = std::filesystem;

using ImageKey = std::pair<int, int>;             // scene_id, im_id
using ImageTargets = std::map<int, int>;           // obj_id -> inst_count

std::string split_of(const ScoreSettings& s, std::string* method) {
  const auto name = parse_bop_results_filename(s.results);
  if (name) *method = name->method;
  if (!s.split.empty()) return s.split;
  if (!name) {
    throw InputError(s.results, "file name",
                     "does not follow bop_toolkit's METHOD_DATASET-SPLIT.csv, so the split is unknown "
                     "(rename the file or give --split)");
  }
  return name->split_type.empty() ? name->split : name->split + "_" + name->split_type;
}

// The targets by image: from a targets file, or every GT instance.
std::map<ImageKey, ImageTargets> load_targets(const ScoreSettings& s, const BopDataset& ds,
                                              const std::string& split, std::string* source) {
  std::string file = s.targets;
  const std::string default_file = (fs::path(s.dataset) / "test_targets_bop19.json").string();
  if (file.empty() && fs::exists(default_file)) file = default_file;
  std::map<ImageKey, ImageTargets> out;
  if (!file.empty()) {
    *source = file;
    for (const TestTarget& t : read_test_targets(file)) out[{t.scene_id, t.im_id}][t.obj_id] = t.inst_count;
    if (out.empty()) throw InputError(file, "", "no targets");
    return out;
  }
  *source = "every GT instance of split " + split;
  for (int scene_id : ds.scene_ids(split)) {
    for (const auto& [im_id, im] : ds.load_scene(split, scene_id).images)
      for (const GtObject& g : im.gt) ++out[{scene_id, im_id}][g.obj_id];
  }
  if (out.empty()) throw InputError(ds.root(), split, "no image of the split has ground truth (scene_gt.json)");
  return out;
}

// Which GTs are valid: per target object, its inst_count most visible
// instances (the toolkit's visib_gt_min = -1; a stable sort by visib_fract,
// unknown visibility last; without scene_gt_info.json the file order).
std::vector<bool> valid_gts(const ImageInfo& im, const ImageTargets& targets) {
  std::vector<int> order(im.gt.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  auto visib = [&](int g) {
    if (im.gt_info.size() != im.gt.size()) return 0.0;
    const double v = im.gt_info[g].visib_fract;
    return std::isfinite(v) ? v : -1.0;
  };
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return visib(a) > visib(b); });
  std::map<int, int> to_add = targets;
  std::vector<bool> valid(im.gt.size(), false);
  for (int g : order) {
    auto it = to_add.find(im.gt[g].obj_id);
    if (it != to_add.end() && it->second > 0) {
      valid[g] = true;
      --it->second;
    }
  }
  return valid;
}

struct Models {
  std::map<int, Mesh> meshes;
  std::map<int, BopModel> bop;
};

void load_models(const BopDataset& ds, const std::map<ImageKey, ImageTargets>& targets,
                 const std::string& targets_source, Models& m) {
  for (const auto& [key, objs] : targets) {
    for (const auto& [obj_id, count] : objs) {
      if (m.bop.count(obj_id)) continue;
      if (!ds.models().count(obj_id)) {
        throw InputError(targets_source, "scene " + std::to_string(key.first) + " image " +
                                             std::to_string(key.second) + " obj_id",
                         "object " + std::to_string(obj_id) + " is not in " + ds.root() + "/models/models_info.json");
      }
      m.meshes.emplace(obj_id, ds.load_model(obj_id));
      BopModel bm;
      bm.mesh = &m.meshes.at(obj_id);
      bm.symmetries = symmetry_transformations(ds.model_info(obj_id));
      bm.diameter = ds.model_info(obj_id).diameter;
      m.bop.emplace(obj_id, std::move(bm));
    }
  }
}

// Only one object's targets and estimates: the per-object recall.
std::vector<BopImageErrors> only_object(const std::vector<BopImageErrors>& images, int obj_id) {
  std::vector<BopImageErrors> out = images;
  for (BopImageErrors& im : out) {
    for (BopTarget& t : im.gts) t.valid = t.valid && t.obj_id == obj_id;
    im.estimates.erase(std::remove_if(im.estimates.begin(), im.estimates.end(),
                                      [&](const BopEstimateErrors& e) { return e.obj_id != obj_id; }),
                       im.estimates.end());
  }
  return out;
}

// The toolkit's average time per image: the mean over the file's images of
// their time, -1 when any estimate has none.
double average_time(const std::vector<BopResultRow>& rows) {
  std::map<ImageKey, double> times;
  for (const BopResultRow& r : rows) {
    if (r.time_s < 0) return -1;
    times.emplace(ImageKey{r.scene_id, r.im_id}, r.time_s);
  }
  double sum = 0;
  for (const auto& [k, t] : times) sum += t;
  return times.empty() ? -1 : sum / static_cast<double>(times.size());
}

// The indices of the rows that estimate a target, by image; the others
// counted in *not_target.
std::map<ImageKey, std::vector<int>> target_rows_by_image(const std::vector<BopResultRow>& rows,
                                                          const std::map<ImageKey, ImageTargets>& targets,
                                                          int* not_target) {
  std::map<ImageKey, std::vector<int>> by_image;
  for (size_t i = 0; i < rows.size(); ++i) {
    const BopResultRow& r = rows[i];
    auto t = targets.find({r.scene_id, r.im_id});
    if (t == targets.end() || !t->second.count(r.obj_id)) {
      ++*not_target;
      continue;
    }
    by_image[{r.scene_id, r.im_id}].push_back(static_cast<int>(i));
  }
  return by_image;
}

// The split's scenes' images, in the order of the targets: a scene is
// loaded when the first of its images is asked for.
class SceneImages {
 public:
  SceneImages(const BopDataset& ds, const std::string& split, const std::string& targets_source)
      : ds_(ds), split_(split), source_(targets_source) {}
  const ImageInfo& image(const ImageKey& key) {
    if (key.first != loaded_scene_) {
      if (!fs::is_directory(ds_.scene_dir(split_, key.first))) {
        throw InputError(source_, "scene " + std::to_string(key.first),
                         "no such scene in " + ds_.scene_dir(split_, key.first));
      }
      scene_ = ds_.load_scene(split_, key.first);
      loaded_scene_ = key.first;
    }
    auto it = scene_.images.find(key.second);
    if (it == scene_.images.end()) {
      throw InputError(source_, "scene " + std::to_string(key.first) + " image " + std::to_string(key.second),
                       "no such image in " + ds_.scene_dir(split_, key.first) + "/scene_camera.json");
    }
    return it->second;
  }

 private:
  const BopDataset& ds_;
  const std::string& split_;
  const std::string& source_;
  int loaded_scene_ = -1;
  SceneInfo scene_;
};

// The error computation's input for one image: its ground truth (the
// targets valid) and the rows `mine` as its estimates.
BopImageInput image_input(const ImageKey& key, const ImageInfo& im, const ImageTargets& objs,
                          const std::vector<BopResultRow>& rows, const std::vector<int>& mine) {
  BopImageInput in;
  in.scene_id = key.first;
  in.im_id = key.second;
  in.K = im.K;
  for (const GtObject& g : im.gt) {
    in.gt_obj_ids.push_back(g.obj_id);
    in.gt_poses.push_back(g.T_cam_model);
  }
  in.gt_valid = valid_gts(im, objs);
  for (int i : mine) in.estimates.push_back(BopEstimate{rows[i].obj_id, rows[i].score, rows[i].T_cam_model});
  return in;
}

// One image's estimates' errors as scored rows (each with its line of the file).
void add_scored(const BopImageErrors& errs, const std::vector<BopResultRow>& rows, const std::vector<int>& mine,
                std::vector<ScoredEstimate>& out) {
  for (const BopEstimateErrors& e : errs.estimates) {
    const BopResultRow& r = rows[mine[e.source]];
    ScoredEstimate se{r.line, r.scene_id, r.im_id, r.obj_id, r.score, {}};
    for (const BopPairErrors& p : e.pairs) se.pairs.push_back(ScoredPair{p.gt, p.mssd_mm, p.mspd_px, p.vsd});
    out.push_back(std::move(se));
  }
}

}  // namespace

ScoreResult score_bop_results(const ScoreSettings& s) {
  ScoreResult res;
  res.results = s.results;
  res.dataset = s.dataset;
  const std::vector<BopResultRow> rows = read_bop_results_csv(s.results);
  if (rows.empty()) throw InputError(s.results, "", "no estimates (bop_toolkit rejects an empty results file)");
  res.rows = static_cast<int>(rows.size());
  res.average_time_s = average_time(rows);
  res.split = split_of(s, &res.method);
  const BopDataset ds(s.dataset);
  if (ds.scene_ids(res.split).empty()) {
    std::string have;
    for (const auto& sp : ds.splits()) have += (have.empty() ? "" : ", ") + sp;
    throw InputError(s.dataset, "split", "no scenes in split '" + res.split + "' (the dataset has: " + have + ")");
  }
  const auto targets = load_targets(s, ds, res.split, &res.targets_source);
  Models models;
  load_models(ds, targets, res.targets_source, models);
  std::map<ImageKey, std::vector<int>> rows_by_image = target_rows_by_image(rows, targets, &res.rows_not_target);

  BopErrorOptions opt;
  opt.compute_vsd = s.vsd;
  opt.vsd.delta_mm = s.vsd_delta_mm;
  std::map<std::pair<int, int>, std::unique_ptr<DepthRenderer>> renderers;  // by image size
  std::vector<BopImageErrors> images;
  SceneImages scenes(ds, res.split, res.targets_source);
  for (const auto& [key, objs] : targets) {
    const ImageInfo& im = scenes.image(key);
    const auto& mine = rows_by_image[key];
    BopImageInput in = image_input(key, im, objs, rows, mine);
    DepthImage depth;
    DepthRenderer* renderer = nullptr;
    if (s.vsd && !in.estimates.empty()) {
      depth = ds.load_depth(res.split, key.first, im);
      in.depth = &depth;
      auto& r = renderers[{im.K.width, im.K.height}];
      if (!r) r = std::make_unique<DepthRenderer>(im.K);
      r->set_intrinsics(im.K);
      renderer = r.get();
    }
    BopImageErrors errs = bop_image_errors(in, models.bop, opt, renderer);
    add_scored(errs, rows, mine, res.errors);
    images.push_back(std::move(errs));
  }
  std::sort(res.errors.begin(), res.errors.end(),
            [](const ScoredEstimate& a, const ScoredEstimate& b) { return a.line < b.line; });
  res.rows_scored = static_cast<int>(res.errors.size());
  res.images = static_cast<int>(images.size());
  BopScoreOptions so;
  if (s.vsd) so.vsd_tau_count = static_cast<int>(opt.vsd.taus.size());
  res.total = bop_scores(images, so);
  for (const auto& [obj_id, m] : models.bop) res.per_object[obj_id] = bop_scores(only_object(images, obj_id), so);
  return res;
}

}  // namespace pb
