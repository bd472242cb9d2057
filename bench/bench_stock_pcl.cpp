// Stock PCL against posebench's recognize(), per recognition method, in one
// process on the same image at the same settings:
//   stock  the method through plain PCL calls, as the PCL tutorials make them
//          (bench_stock_pcl_methods.h lists them), plus here: PPF
//          (PPFEstimation + PPFHashMapSearch offline, PPFRegistration online)
//          and, for every method, IterativeClosestPoint (point-to-point) per
//          hypothesis against the whole preprocessed scene (no crop, one
//          ICP object per hypothesis as the tutorials), the most inliers wins;
//   ours   pb::recognize(depth, K, model, settings) (recognition/pipeline.h),
//          the model trained as bench_pipeline does (test::train).
// Image: the first image of configs/scenes/table_astra.yaml (simulated Astra,
// 640x480); object: ls5. Settings: the table_astra section of
// configs/bench/pipeline.yaml over the defaults (8 training views, voxel
// 10 mm, keypoint voxel 15 mm, Hough bin 50 mm, ...), refinement icp, but
// ESF at 20,000 triples (pcl::ESFEstimation's fixed count; the bench config
// draws one per point). Stock
// PCL gets the same training views (scenes/views.h), preprocessed and
// described by the same stock calls; both models are trained once, outside
// the timing: only the online computation (depth image -> pose) is timed.
// cesf is left out: it is the project's own combination (ESF per CVFH stable
// region) with no stock PCL counterpart.
//
// Each iteration runs ours, then stock, on the same image. Counters: ours_ms,
// stock_ms (wall time per call), ratio = stock_ms / ours_ms, *_cpu_ms (CPU
// time of the process during the call: shows multithreading or a busy
// machine), *_found (translation error to the ground truth < 50 mm),
// *_t_err_mm, *_hyps (hypotheses refined), ours_<stage>_ms (ours per stage:
// pre(process), desc(ribe), match, group (with the initial pose), refine,
// verify), stock_<stage>_ms (stock's: pre, hyp (describe to initial pose),
// refine (ICP and the inlier counts)). The Time column is ours + stock.
// The process keeps freed memory (core/memory.h, as a `posebench run`
// worker does; bench/keep_freed_memory.cpp), for both sides: it took ours'
// preprocessing from 9-13 ms to 8 ms here and left stock's times within
// their run-to-run spread.
// One thread (ours is also told local.threads = 1: its FPFH / SHOT /
// matching otherwise use every core whatever OMP_NUM_THREADS says; stock
// uses the non-OMP PCL classes):
//   OMP_NUM_THREADS=1 build/bench/bench_stock_pcl --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>

#include <chrono>
#include <ctime>
#include <limits>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>

#include <pcl/console/print.h>

#include "bench_stock_pcl_methods.h"
#include "core/yaml.h"
#include "recognition/pipeline.h"
#include "../tests/recognition_train_util.h"
#include "scenes/generator.h"
#include "scenes/scene_config.h"
#include "scenes/views.h"

namespace stock {

// Pose (mm) -> 4x4 transform in metres.
Mat4 to_m(const pb::Pose& T) {
  Mat4 M = T.matrix().cast<float>();
  M.block<3, 1>(0, 3) *= kM;
  return M;
}

// Depth image -> cloud of the valid pixels (pinhole back-projection, metres).
Cloud::Ptr depth_to_cloud(const pb::DepthImage& d, const pb::Intrinsics& K) {
  Cloud::Ptr c(new Cloud);
  c->reserve(d.z.size());
  for (int v = 0; v < d.height; ++v)
    for (int u = 0; u < d.width; ++u) {
      const double z = d.at(u, v);
      if (z > 0) c->push_back(Point(float((u - K.cx) * z / K.fx * kM), float((v - K.cy) * z / K.fy * kM), float(z * kM)));
    }
  return c;
}

// PPF: the training views merged in the model frame, downsampled, paired
// (pcl::PPFEstimation) and hashed (pcl::PPFHashMapSearch) offline; online,
// pcl::PPFRegistration votes and clusters and returns its best pose.
class PpfMethod : public Method {
 public:
  PpfMethod(const Model& m, const pb::PpfSettings& s) : s_(s), m_(m) {
    // Views with normals into the model frame (pcl::concatenateFields,
    // pcl::transformPointCloudWithNormals), merged.
    pcl::PointCloud<pcl::PointNormal>::Ptr merged(new pcl::PointCloud<pcl::PointNormal>);
    for (size_t v = 0; v < m.views.size(); ++v) {
      pcl::PointCloud<pcl::PointNormal> view, in_model;
      pcl::concatenateFields(*m.views[v].cloud, *m.views[v].normals, view);
      pcl::transformPointCloudWithNormals(view, in_model, Mat4(m.T_view_model[v].inverse()));
      *merged += in_model;
    }
    // pcl::VoxelGrid, the leaf grown until about model_points points remain;
    // the averaged normals scaled back to unit length.
    pcl::VoxelGrid<pcl::PointNormal> vg;
    vg.setInputCloud(merged);
    for (float leaf = 0.002f; model_->empty() || model_->size() > size_t(s.model_points); leaf *= 1.05f) {
      vg.setLeafSize(leaf, leaf, leaf);
      vg.filter(*model_);
    }
    for (auto& p : *model_) p.getNormalVector3fMap().normalize();
    float diameter = 0;
    for (const auto& a : *model_)
      for (const auto& b : *model_) diameter = std::max(diameter, (a.getVector3fMap() - b.getVector3fMap()).norm());
    // Pair features of every model pair: pcl::PPFEstimation; their hash map:
    // pcl::PPFHashMapSearch (angle step, distance step).
    pcl::PointCloud<pcl::PPFSignature>::Ptr features(new pcl::PointCloud<pcl::PPFSignature>);
    pcl::PPFEstimation<pcl::PointNormal, pcl::PointNormal, pcl::PPFSignature> est;
    est.setInputCloud(model_);
    est.setInputNormals(model_);
    est.compute(*features);
    search_.reset(new pcl::PPFHashMapSearch(float(s.angle_step_deg * M_PI / 180.0),
                                            float(s.distance_step_fraction) * diameter));
    search_->setInputFeatureCloud(features);
  }

  std::vector<Hyp> hypothesize(const Prepared& scene) const override {
    // The scene's points and normals as one cloud: pcl::concatenateFields.
    pcl::PointCloud<pcl::PointNormal>::Ptr sc(new pcl::PointCloud<pcl::PointNormal>);
    pcl::concatenateFields(*scene.cloud, *scene.normals, *sc);
    // pcl::PPFRegistration: every n-th scene point a reference (n = 1 /
    // scene_reference_fraction), pose clustering thresholds from the settings.
    pcl::PPFRegistration<pcl::PointNormal, pcl::PointNormal> reg;
    reg.setSceneReferencePointSamplingRate(unsigned(std::max(1.0, std::round(1.0 / s_.scene_reference_fraction))));
    reg.setPositionClusteringThreshold(float(s_.position_cluster_mm * kM));
    reg.setRotationClusteringThreshold(float(s_.rotation_cluster_deg * M_PI / 180.0));
    reg.setSearchMethod(search_);
    reg.setInputSource(model_);
    reg.setInputTarget(sc);
    pcl::PointCloud<pcl::PointNormal> aligned;
    reg.align(aligned);
    Hyp h{reg.getFinalTransformation(), 0, 1.0};
    // ICP source: the training view seen from the pose's direction (as ours).
    const Eigen::Vector3f cam = -(h.T.block<3, 3>(0, 0).transpose() * h.T.block<3, 1>(0, 3)).normalized();
    float best = -2;
    for (size_t v = 0; v < m_.T_view_model.size(); ++v) {
      const Mat4& T = m_.T_view_model[v];
      const float c = cam.dot(-(T.block<3, 3>(0, 0).transpose() * T.block<3, 1>(0, 3)).normalized());
      if (c > best) {
        best = c;
        h.view = int(v);
      }
    }
    return {h};
  }

 private:
  pb::PpfSettings s_;
  const Model& m_;
  pcl::PointCloud<pcl::PointNormal>::Ptr model_{new pcl::PointCloud<pcl::PointNormal>};
  pcl::PPFHashMapSearch::Ptr search_;
};

// Offline: the training views preprocessed by the stock calls, then the method.
std::unique_ptr<Model> train(const pb::TrainingViews& tv, const pb::RecognitionSettings& s) {
  auto m = std::make_unique<Model>();
  for (const pb::TrainingView& v : tv.views) {
    m->views.push_back(preprocess(depth_to_cloud(v.depth, v.K), s.preprocess, false));
    m->T_view_model.push_back(to_m(v.T_cam_model));
    Cloud::Ptr in_model(new Cloud);
    pcl::transformPointCloud(*m->views.back().cloud, *in_model, Mat4(m->T_view_model.back().inverse()));
    m->view_model.push_back(in_model);
  }
  const std::string& d = s.descriptor;
  if (d == "fpfh") m->method = std::make_unique<LocalMethod<pcl::FPFHSignature33>>(*m, s.local);
  else if (d == "shot") m->method = std::make_unique<LocalMethod<pcl::SHOT352>>(*m, s.local);
  else if (d == "cvfh") m->method = std::make_unique<GlobalMethod<pcl::VFHSignature308>>(GlobalKind::kCvfh, *m, s.global);
  else if (d == "ourcvfh")
    m->method = std::make_unique<GlobalMethod<pcl::VFHSignature308>>(GlobalKind::kOurCvfh, *m, s.global);
  else if (d == "esf") m->method = std::make_unique<GlobalMethod<pcl::ESFSignature640>>(GlobalKind::kEsf, *m, s.global);
  else if (d == "ppf") m->method = std::make_unique<PpfMethod>(*m, s.ppf);
  else throw std::invalid_argument("no stock PCL counterpart for " + d);
  return m;
}

struct Outcome {
  bool ok = false;
  Mat4 T = Mat4::Identity();  // T_cam_model, metres
  size_t hypotheses = 0;
  double pre_s = 0, hyp_s = 0, refine_s = 0;  // stage times (refine: ICP and the inlier counts)
};

// Online: depth image -> preprocessed scene -> hypotheses -> ICP -> inliers.
Outcome recognize(const pb::DepthImage& depth, const pb::Intrinsics& K, const Model& m,
                  const pb::RecognitionSettings& s) {
  using Clock = std::chrono::steady_clock;
  const auto since = [](Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); };
  Outcome o;
  auto t = Clock::now();
  const Prepared scene = preprocess(depth_to_cloud(depth, K), s.preprocess, true);
  o.pre_s = since(t);
  if (scene.cloud->size() < 3) return o;
  t = Clock::now();
  const std::vector<Hyp> hyps = m.method->hypothesize(scene);
  o.hyp_s = since(t);
  t = Clock::now();
  o.hypotheses = hyps.size();
  // Verification: pcl::KdTreeFLANN over the scene; an inlier is a model
  // point within inlier_threshold of its nearest scene point.
  pcl::KdTreeFLANN<Point> kd;
  kd.setInputCloud(scene.cloud);
  const float thr2 = float(s.verify.inlier_threshold_mm * kM) * float(s.verify.inlier_threshold_mm * kM);
  pcl::Indices idx(1);
  std::vector<float> d2(1);
  int best = 0;
  for (const Hyp& h : hyps) {
    if (!h.T.allFinite()) continue;
    // Refinement: pcl::IterativeClosestPoint (point-to-point), the view in
    // the model frame onto the whole scene, from the hypothesis.
    pcl::IterativeClosestPoint<Point, Point> icp;
    icp.setInputSource(m.view_model[size_t(h.view)]);
    icp.setInputTarget(scene.cloud);
    icp.setMaxCorrespondenceDistance(s.refine.max_correspondence_mm * kM);
    icp.setMaximumIterations(s.refine.max_iterations);
    icp.setTransformationEpsilon(s.refine.transformation_epsilon);
    icp.setTransformationRotationEpsilon(std::cos(s.refine.rotation_epsilon_deg * M_PI / 180.0));
    icp.setEuclideanFitnessEpsilon(s.refine.fitness_epsilon);  // PCL: relative MSE change, as ours
    icp.setUseReciprocalCorrespondences(s.refine.reciprocal_correspondences);
    Cloud aligned;
    icp.align(aligned, h.T);
    int inliers = 0;
    for (const Point& p : aligned)
      if (kd.nearestKSearch(p, 1, idx, d2) == 1 && d2[0] <= thr2) ++inliers;
    if (inliers > best) {
      best = inliers;
      o.ok = true;
      o.T = icp.getFinalTransformation();
    }
  }
  o.refine_s = since(t);
  return o;
}

}  // namespace stock

namespace {

using namespace pb;

constexpr double kFoundMm = 50.0;

struct Fixture {
  DepthImage depth;
  Intrinsics K;
  Pose gt;
  Mesh mesh;
  RecognitionSettings settings;  // table_astra's, descriptor unset
  TrainingViews views;           // for the stock models
};

RecognitionSettings table_astra_settings() {
  const std::string path = std::string(POSEBENCH_SOURCE_DIR) + "/configs/bench/pipeline.yaml";
  const YamlNode scenes = YamlNode::load_file(path)["scenes"];
  for (size_t i = 0; i < scenes.size(); ++i)
    if (scenes.at(i).get<std::string>("name") == "table_astra") {
      RecognitionSettings s = parse_recognition_settings(scenes.at(i)["settings"]);
      s.refinement = "icp";
      s.global.esf_samples_from_points = false;  // pcl::ESFEstimation draws 20,000, with no setting for it
      s.local.threads = 1;  // one thread (see the header comment); results do not depend on it
      return s;
    }
  throw std::runtime_error(path + ": no table_astra scene");
}

const Fixture& fixture() {
  static const Fixture f = [] {
    pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);  // PPFRegistration prints INFO lines
    Fixture f;
    const std::string path = std::string(POSEBENCH_SOURCE_DIR) + "/configs/scenes/table_astra.yaml";
    SceneGenerator gen(parse_scene_settings(YamlNode::load_file(path)));
    const GeneratedImage g = gen.generate(0);
    f.depth = g.depth;
    f.K = g.info.K;
    f.gt = g.info.gt.at(0).T_cam_model;
    f.mesh = gen.model("ls5").mesh;
    f.settings = table_astra_settings();
    f.views = training_views(f.mesh, f.settings.views, "ls5");
    return f;
  }();
  return f;
}

RecognitionSettings settings_for(const std::string& descriptor) {
  RecognitionSettings s = fixture().settings;
  s.descriptor = descriptor;
  return s;
}

// Both models of a descriptor, trained on first use (not timed).
struct Models {
  std::shared_ptr<const TrainedModel> ours;
  std::unique_ptr<stock::Model> stock;
};

const Models& models(const std::string& descriptor) {
  static std::map<std::string, Models> all;
  Models& m = all[descriptor];
  if (!m.ours) {
    const RecognitionSettings s = settings_for(descriptor);
    m.ours = test::train(fixture().mesh, s, TrainOptions{}, nullptr, "ls5");
    m.stock = stock::train(fixture().views, s);
  }
  return m;
}

double t_err_mm(const Vec3& t, const Pose& gt) { return (t - gt.t).norm(); }

void BM_StockVsOurs(benchmark::State& state, const std::string& descriptor) {
  using Clock = std::chrono::steady_clock;
  const Fixture& f = fixture();
  const RecognitionSettings s = settings_for(descriptor);
  const Models& m = models(descriptor);
  // One untimed call each: lazy initialisations and caches on both sides.
  RecognitionResult ours = recognize(f.depth, f.K, *m.ours, s);
  stock::Outcome st = stock::recognize(f.depth, f.K, *m.stock, s);
  double ours_s = 0, stock_s = 0, ours_cpu = 0, stock_cpu = 0;
  StageTimes ours_stages;  // summed over the iterations
  double stock_pre = 0, stock_hyp = 0, stock_refine = 0;
  for (auto _ : state) {
    const auto t0 = Clock::now();
    const std::clock_t c0 = std::clock();
    ours = recognize(f.depth, f.K, *m.ours, s);
    const auto t1 = Clock::now();
    const std::clock_t c1 = std::clock();
    st = stock::recognize(f.depth, f.K, *m.stock, s);
    const auto t2 = Clock::now();
    const std::clock_t c2 = std::clock();
    benchmark::DoNotOptimize(ours.T_cam_model.t.data());
    benchmark::DoNotOptimize(st.T.data());
    const double a = std::chrono::duration<double>(t1 - t0).count(), b = std::chrono::duration<double>(t2 - t1).count();
    ours_s += a;
    ours_stages.preprocess += ours.times.preprocess;
    ours_stages.describe += ours.times.describe;
    ours_stages.match += ours.times.match;
    ours_stages.group += ours.times.group + ours.times.initial_pose;
    ours_stages.refine += ours.times.refine;
    ours_stages.verify += ours.times.verify;
    stock_s += b;
    stock_pre += st.pre_s;
    stock_hyp += st.hyp_s;
    stock_refine += st.refine_s;
    ours_cpu += double(c1 - c0) / CLOCKS_PER_SEC;
    stock_cpu += double(c2 - c1) / CLOCKS_PER_SEC;
    state.SetIterationTime(a + b);
  }
  const double n = double(state.iterations());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double ours_err = ours.status == "ok" ? t_err_mm(ours.T_cam_model.t, f.gt) : nan;
  const double stock_err = st.ok ? t_err_mm(st.T.block<3, 1>(0, 3).cast<double>() / stock::kM, f.gt) : nan;
  state.counters["ours_ms"] = 1e3 * ours_s / n;
  state.counters["stock_ms"] = 1e3 * stock_s / n;
  state.counters["ratio"] = stock_s / ours_s;
  state.counters["ours_cpu_ms"] = 1e3 * ours_cpu / n;
  state.counters["stock_cpu_ms"] = 1e3 * stock_cpu / n;
  state.counters["ours_found"] = ours_err < kFoundMm ? 1 : 0;
  state.counters["stock_found"] = stock_err < kFoundMm ? 1 : 0;
  state.counters["ours_t_err_mm"] = ours_err;
  state.counters["stock_t_err_mm"] = stock_err;
  state.counters["ours_hyps"] = double(ours.hypotheses.size());
  // Ours per stage (ms per call; group includes the initial pose): where
  // the ratio is decided.
  state.counters["ours_pre_ms"] = 1e3 * ours_stages.preprocess / n;
  state.counters["ours_desc_ms"] = 1e3 * ours_stages.describe / n;
  state.counters["ours_match_ms"] = 1e3 * ours_stages.match / n;
  state.counters["ours_group_ms"] = 1e3 * ours_stages.group / n;
  state.counters["ours_refine_ms"] = 1e3 * ours_stages.refine / n;
  state.counters["ours_verify_ms"] = 1e3 * ours_stages.verify / n;
  state.counters["stock_hyps"] = double(st.hypotheses);
  // Stock per stage: preprocessing, hypotheses (describe, match, group and
  // initial pose), refinement with the inlier counts (ours: refine + verify).
  state.counters["stock_pre_ms"] = 1e3 * stock_pre / n;
  state.counters["stock_hyp_ms"] = 1e3 * stock_hyp / n;
  state.counters["stock_refine_ms"] = 1e3 * stock_refine / n;
}

void Configure(benchmark::internal::Benchmark* b) { b->UseManualTime()->Unit(benchmark::kMillisecond); }

}  // namespace

BENCHMARK_CAPTURE(BM_StockVsOurs, fpfh, std::string("fpfh"))->Apply(Configure);
BENCHMARK_CAPTURE(BM_StockVsOurs, shot, std::string("shot"))->Apply(Configure);
BENCHMARK_CAPTURE(BM_StockVsOurs, cvfh, std::string("cvfh"))->Apply(Configure);
BENCHMARK_CAPTURE(BM_StockVsOurs, ourcvfh, std::string("ourcvfh"))->Apply(Configure);
BENCHMARK_CAPTURE(BM_StockVsOurs, esf, std::string("esf"))->Apply(Configure);
BENCHMARK_CAPTURE(BM_StockVsOurs, ppf, std::string("ppf"))->Apply(Configure);

BENCHMARK_MAIN();
