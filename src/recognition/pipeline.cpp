// The recognition pipeline (thesis 1.4, the system overview), online part:
// recognize() preprocesses the scene, lets the descriptor method
// hypothesize, refines every hypothesis (or the refine.max_hypotheses most
// promising ones), counts its inliers and keeps the one
// with the most; refine_from() is registration alone (Table 4.9, Figure
// 4.12). Training and the method registry: training.cpp, registry.cpp.
#include "recognition/pipeline.h"

#include <algorithm>
#include <cmath>
#include <exception>

#include "core/random.h"
#include "core/timer.h"
#include "recognition/model.h"
#include "recognition/registry.h"

namespace pb {

namespace {

constexpr size_t kMinScenePoints = 3;

// Random streams of one call (derive_seed ids).
enum Stream : uint64_t { kStreamScene = 11, kStreamMethod = 12, kStreamRefine = 13, kStreamScreen = 14 };

bool finite_pose(const Pose& p) { return p.R.allFinite() && p.t.allFinite(); }

void check_call(const DepthImage& depth, const Intrinsics& K, const TrainedModel& model,
                const RecognitionSettings& s) {
  if (!depth.fits(K))
    throw InputError("", "depth", "image is " + std::to_string(depth.width) + "x" + std::to_string(depth.height) +
                                      " but the intrinsics are for " + std::to_string(K.width) + "x" +
                                      std::to_string(K.height));
  if (s.descriptor != model.descriptor)
    throw InputError("", "descriptor", "the model was trained for '" + model.descriptor + "', the settings ask for '" +
                                           s.descriptor + "'");
  refinement_entry(s.refinement);  // InputError for unknown names
}

// The preprocessed scene; empty (with res.message set) when too few points.
PointSet prepare_scene(const DepthImage& depth, const Intrinsics& K, const RecognitionSettings& s,
                       RecognitionResult& res) {
  Timer timer;
  const OrganizedCloud cloud = OrganizedCloud::from_depth(depth, K);
  PointSet scene = preprocess_scene(cloud, s.preprocess, derive_seed(s.seed, {kStreamScene}));
  res.times.preprocess = timer.seconds();
  if (scene.size() < kMinScenePoints) {
    res.message = "no scene points after filtering (" + std::to_string(cloud.valid_count()) + " valid pixels, " +
                  std::to_string(scene.size()) + " points after range cut, voxel grid, plane removal and normals)";
    scene = PointSet();
  }
  return scene;
}

// Refines every hypothesis independently (one random stream each, one
// output slot each), in parallel over OpenMP threads: the result does not
// depend on the thread count. stream[i]: hypothesis i's position in the
// method's list (its random stream, the same whether or not others were
// dropped before refinement).
// sources: hypothesis i's model points, when given (screening's subsets);
// else its view's model cloud. index: verification's, over the scene's
// points (each hypothesis's crop tree is cut from it).
void refine_all(std::vector<Hypothesis>& hyps, const std::vector<uint64_t>& stream, const TrainedModel& model,
                const PointSet& scene, const PointIndex& index, const RecognitionSettings& s,
                const std::vector<PointSet>* sources = nullptr) {
  for (const auto& h : hyps) model.model_cloud(h.view);  // throws for a view index out of range
  const std::unique_ptr<Refiner> refiner = make_refiner(s.refinement, s.refine);
  const long nh = static_cast<long>(hyps.size());
  std::vector<std::exception_ptr> errors(hyps.size());
#pragma omp parallel for schedule(dynamic, 1)
  for (long i = 0; i < nh; ++i) {
    try {
      Hypothesis& h = hyps[static_cast<size_t>(i)];
      const PointSet& source = sources ? (*sources)[static_cast<size_t>(i)] : model.model_cloud(h.view);
      const RefineResult r = refine_pose(refiner.get(), source, scene, h.T_cam_model, s.refine,
                                         derive_seed(s.seed, {kStreamRefine, stream[static_cast<size_t>(i)]}),
                                         &index.tree());
      if (finite_pose(r.T_cam_model)) {
        h.T_cam_model = r.T_cam_model;
        h.refined = s.refinement != "none";
      }
    } catch (...) {
      errors[static_cast<size_t>(i)] = std::current_exception();
    }
  }
  for (const auto& e : errors)
    if (e) std::rethrow_exception(e);  // the first failing hypothesis, whatever the thread count
}

// A hypothesis's score for ranking: NaN (no score) ranks last.
double score_of(const Hypothesis& h) { return std::isnan(h.score) ? -HUGE_VAL : h.score; }

// Counts the inliers within `threshold_mm` of every hypothesis, or of those
// `which` marks (in parallel; one slot each).
void count_all(std::vector<Hypothesis>& hyps, const TrainedModel& model, const PointIndex& index,
               const VerifySettings& v, double threshold_mm, const std::vector<char>* which = nullptr) {
  const long nh = static_cast<long>(hyps.size());
#pragma omp parallel for schedule(dynamic, 1)
  for (long i = 0; i < nh; ++i) {
    if (which && !(*which)[static_cast<size_t>(i)]) continue;
    Hypothesis& h = hyps[static_cast<size_t>(i)];
    h.inliers = count_inliers(model.verify_cloud(h.view, v).points, h.T_cam_model, index, threshold_mm);
  }
}

// Which hypotheses share their verification with another one (where the
// ranking compares inliers).
std::vector<char> tied(const std::vector<Hypothesis>& hyps) {
  std::vector<size_t> by(hyps.size());
  for (size_t i = 0; i < by.size(); ++i) by[i] = i;
  std::sort(by.begin(), by.end(), [&](size_t a, size_t b) { return hyps[a].verification < hyps[b].verification; });
  std::vector<char> out(hyps.size(), 0);
  for (size_t k = 1; k < by.size(); ++k)
    if (hyps[by[k]].verification == hyps[by[k - 1]].verification) out[by[k]] = out[by[k - 1]] = 1;
  return out;
}

// Computes every hypothesis's verification (verify.score: inliers, or the
// depth evidence of visibility) and inliers; returns the order verification
// ranks them in: verification first; ties by inliers, score, then view
// index, then the method's order. inliers_for_ties: with visibility, only
// the hypotheses whose verification ties have their inliers counted (the
// others' are left as they were: the order is the same, their counts are
// not needed; screening's ranking).
std::vector<size_t> verification_order(std::vector<Hypothesis>& hyps, const TrainedModel& model,
                                       const PointIndex& index, const VerifySettings& v, const DepthImage& depth,
                                       const Intrinsics& K, double spacing_mm, bool inliers_for_ties = false) {
  const bool visibility = v.score == "visibility";
  if (!visibility) count_all(hyps, model, index, v, v.inlier_threshold_mm);
  for (Hypothesis& h : hyps)
    h.verification = visibility ? visibility_score(model.verify_cloud(h.view, v), h.T_cam_model, depth, K, v,
                                                   spacing_mm)
                                : h.inliers;
  if (visibility) {
    const std::vector<char> which = inliers_for_ties ? tied(hyps) : std::vector<char>(hyps.size(), 1);
    count_all(hyps, model, index, v, v.inlier_threshold_mm, &which);
  }
  std::vector<size_t> order(hyps.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    const Hypothesis &x = hyps[a], &y = hyps[b];
    if (x.verification != y.verification) return x.verification > y.verification;
    if (x.inliers != y.inliers) return x.inliers > y.inliers;
    if (score_of(x) != score_of(y)) return score_of(x) > score_of(y);
    if (x.view != y.view) return x.view < y.view;
    return a < b;
  });
  return order;
}

std::vector<Hypothesis> verify_and_rank(std::vector<Hypothesis> hyps, const TrainedModel& model,
                                        const PointIndex& index, const VerifySettings& v, const DepthImage& depth,
                                        const Intrinsics& K, double spacing_mm) {
  std::vector<Hypothesis> ranked;
  for (size_t i : verification_order(hyps, model, index, v, depth, K, spacing_mm)) ranked.push_back(hyps[i]);
  return ranked;
}

// RefineSettings::max_hypotheses: keeps the hypotheses verification ranks
// first (verification_order), in the method's order: at their initial pose,
// or, with refine.screen_points, after a registration of a seeded random
// subset of that many of their model points (the kept ones are then refined
// on all their points from the screened pose). Returns the kept hypotheses'
// positions in the method's list.
std::vector<uint64_t> keep_most_promising(std::vector<Hypothesis>& hyps, const TrainedModel& model,
                                          const PointSet& scene, const PointIndex& index, const DepthImage& depth,
                                          const Intrinsics& K, const RecognitionSettings& s) {
  const size_t keep = static_cast<size_t>(s.refine.max_hypotheses);
  std::vector<uint64_t> kept_at(hyps.size());
  for (size_t i = 0; i < kept_at.size(); ++i) kept_at[i] = i;
  if (keep == 0 || hyps.size() <= keep) return kept_at;
  if (s.refine.screen_points > 0) {
    std::vector<PointSet> sources;
    for (size_t i = 0; i < hyps.size(); ++i) {
      const PointSet& cloud = model.model_cloud(hyps[i].view);
      const std::vector<size_t> pick = sample_indices(cloud.size(), s.refine.screen_points,
                                                      derive_seed(s.seed, {kStreamScreen, static_cast<uint64_t>(i)}));
      sources.push_back(subset(cloud, std::vector<int>(pick.begin(), pick.end())));
    }
    refine_all(hyps, kept_at, model, scene, index, s, &sources);
  }
  std::vector<size_t> order = verification_order(hyps, model, index, s.verify, depth, K, s.preprocess.voxel_mm,
                                                         /*inliers_for_ties=*/true);
  order.resize(keep);
  std::sort(order.begin(), order.end());
  std::vector<Hypothesis> kept;
  kept_at.clear();
  for (size_t i : order) {
    kept.push_back(hyps[i]);
    kept_at.push_back(i);
  }
  hyps = std::move(kept);
  return kept_at;
}

// The acceptance rule (VerifySettings): a hypothesis needs an inlier and at
// least min_inlier_fraction of its model points as inliers. Returns why the
// ranked-first hypothesis `h` fails it, "" when it passes.
std::string rejection(const Hypothesis& h, const TrainedModel& model, const VerifySettings& v) {
  if (h.inliers < 1) return "no hypothesis has an inlier within " + std::to_string(v.inlier_threshold_mm) + " mm";
  const size_t model_points = model.verify_cloud(h.view, v).size();
  if (static_cast<double>(h.inliers) < v.min_inlier_fraction * static_cast<double>(model_points))
    return "the best hypothesis has " + std::to_string(h.inliers) + " inliers of " + std::to_string(model_points) +
           " model points, below min_inlier_fraction " + std::to_string(v.min_inlier_fraction);
  return "";
}

// Further instances (VerifySettings::max_instances) after the accepted best,
// in rank order: accepted by the same rule, at least instance_min_ratio of
// the best's verification, farther than instance_separation_mm from every
// instance taken.
void collect_instances(const TrainedModel& model, const VerifySettings& v, RecognitionResult& res) {
  const Hypothesis& best = res.instances.front();
  for (size_t i = 1; i < res.hypotheses.size(); ++i) {
    if (v.max_instances > 0 && res.instances.size() >= static_cast<size_t>(v.max_instances)) break;
    const Hypothesis& h = res.hypotheses[i];
    if (!(h.verification > 0) || !(h.verification >= v.instance_min_ratio * best.verification)) continue;
    if (!rejection(h, model, v).empty()) continue;
    bool separate = true;
    for (const Hypothesis& taken : res.instances)
      separate = separate && (h.T_cam_model.t - taken.T_cam_model.t).norm() > v.instance_separation_mm;
    if (separate) res.instances.push_back(h);
  }
}

void accept_best(const TrainedModel& model, const VerifySettings& v, RecognitionResult& res) {
  const Hypothesis& best = res.hypotheses.front();
  res.message = rejection(best, model, v);
  if (!res.message.empty()) return;
  res.status = "ok";
  res.T_cam_model = best.T_cam_model;
  res.score = best.score;
  res.inliers = best.inliers;
  res.instances.push_back(best);
  collect_instances(model, v, res);
}

// The training view seen from the direction closest to the one `init`
// implies: the camera -> object ray expressed in the model frame.
int nearest_view(const TrainedModel& model, const Pose& init) {
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
  return best_view;
}

// The common tail of recognize and refine_from: refine, verify, accept.
void refine_verify_accept(std::vector<Hypothesis> hyps, const TrainedModel& model, const PointSet& scene,
                          const DepthImage& depth, const Intrinsics& K, const RecognitionSettings& s,
                          RecognitionResult& res) {
  Timer timer;
  const PointIndex index(scene.points);
  res.times.verify = timer.seconds();
  timer.reset();
  const std::vector<uint64_t> stream = keep_most_promising(hyps, model, scene, index, depth, K, s);
  refine_all(hyps, stream, model, scene, index, s);
  res.times.refine = timer.seconds();
  timer.reset();
  res.hypotheses = verify_and_rank(std::move(hyps), model, index, s.verify, depth, K, s.preprocess.voxel_mm);
  res.times.verify += timer.seconds();
  accept_best(model, s.verify, res);
}

}  // namespace

RecognitionResult recognize(const DepthImage& depth, const Intrinsics& K, const TrainedModel& model,
                            const RecognitionSettings& settings) {
  RecognitionResult res;
  check_call(depth, K, model, settings);
  if (!model.method) {
    res.message = "empty model: " + model.empty_reason;
    return res;
  }
  const RecognitionSettings s = resolve_lengths(settings, model.diameter_mm);
  const PointSet scene = prepare_scene(depth, K, s, res);
  if (scene.empty()) return res;

  std::vector<Hypothesis> hyps =
      model.method->hypothesize(scene, model.views, derive_seed(s.seed, {kStreamMethod}), res.times);
  hyps.erase(std::remove_if(hyps.begin(), hyps.end(), [](const Hypothesis& h) { return !finite_pose(h.T_cam_model); }),
             hyps.end());
  if (hyps.empty()) {
    res.message = "the " + model.descriptor + " method formed no hypothesis (" + std::to_string(scene.size()) +
                  " scene points)";
    return res;
  }
  refine_verify_accept(std::move(hyps), model, scene, depth, K, s, res);
  return res;
}

RecognitionResult refine_from(const DepthImage& depth, const Intrinsics& K, const TrainedModel& model,
                              const RecognitionSettings& settings, const Pose& init) {
  RecognitionResult res;
  check_call(depth, K, model, settings);
  if (model.views.empty()) {
    res.message = "empty model: " + model.empty_reason;
    return res;
  }
  const RecognitionSettings s = resolve_lengths(settings, model.diameter_mm);
  const PointSet scene = prepare_scene(depth, K, s, res);
  if (scene.empty()) return res;
  std::vector<Hypothesis> hyps(1);
  hyps[0].T_cam_model = init;
  hyps[0].view = nearest_view(model, init);
  refine_verify_accept(std::move(hyps), model, scene, depth, K, s, res);
  return res;
}

}  // namespace pb
