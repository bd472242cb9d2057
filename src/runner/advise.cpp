#include "runner/advise.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <map>
#include <sstream>
#include <tuple>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/random.h"
#include "core/rotation.h"
#include "io/mesh_io.h"
#include "io/png.h"
#include "models/registry.h"
#include "recognition/kdtree.h"
#include "render/sensor.h"

namespace pb {

namespace fs = std::filesystem;

namespace {

std::string num(double v) {
  std::ostringstream o;
  o << std::setprecision(6) << v;
  return o.str();
}

std::string list(const std::vector<std::string>& v) {
  std::string s = "[";
  for (size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + v[i];
  return s + "]";
}

std::string list(const std::vector<double>& v) {
  std::string s = "[";
  for (size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + num(v[i]);
  return s + "]";
}

// A YAML scalar for any text: a JSON string is a YAML double-quoted scalar.
std::string quoted(const std::string& text) { return nlohmann::json(text).dump(); }

// A registry name from the mesh file's stem (letters, digits, _).
std::string object_name(const std::string& mesh) {
  std::string n = fs::path(mesh).stem().string();
  for (char& c : n)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return n.empty() ? "target" : n;
}

// The half turns of a box and the axis of a cylinder, as in models/models.yaml.
const char* kBoxSymmetries =
    "    symmetries_discrete:\n"
    "      - [[-1, 0, 0, 0], [0, -1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]\n"
    "      - [[1, 0, 0, 0], [0, -1, 0, 0], [0, 0, -1, 0], [0, 0, 0, 1]]\n"
    "      - [[-1, 0, 0, 0], [0, 1, 0, 0], [0, 0, -1, 0], [0, 0, 0, 1]]\n";
const char* kAxisSymmetry = "    symmetries_continuous:\n      - {axis: [0, 0, 1], offset: [0, 0, 0]}\n";

std::string registry_yaml(const AdviseOptions& opt, const std::string& name, double extent) {
  std::ostringstream y;
  y << "# Written by `posebench advise`: the user's mesh and generated distractors of its size.\n"
    << "models:\n"
    << "  " << name << ":\n    obj_id: 1\n    source: " << quoted(fs::absolute(opt.mesh).string())
    << "\n    scale: " << num(opt.mesh_scale) << "\n    up: " << quoted(opt.up) << "\n    role: target\n"
    << "  box:\n    obj_id: 2\n    source: generated:box:120x80x60\n    fit_size: " << num(0.8 * extent)
    << "\n    role: distractor\n"
    << kBoxSymmetries << "  cylinder:\n    obj_id: 3\n    source: generated:cylinder:70x120\n    fit_size: "
    << num(0.8 * extent) << "\n    role: distractor\n"
    << kAxisSymmetry << "  boletus:\n    obj_id: 4\n    source: generated:boletus\n    fit_size: " << num(0.7 * extent)
    << "\n    role: distractor\n"
    << kAxisSymmetry;
  return y.str();
}

std::string experiment_yaml(const std::string& name, const AdviseOptions& opt, const AdviceInputs& in,
                            const std::vector<std::string>& descriptors, const std::vector<std::string>& refinements,
                            const std::vector<double>& factors) {
  std::ostringstream y;
  y << "# Written by `posebench advise` (" << fs::path(opt.mesh).filename().string() << ", " << opt.sensor << ", "
    << opt.images << " images, seed " << opt.seed << "). Run: posebench run THIS.yaml --out DIR\n"
    << "name: " << name << "\nseed: " << opt.seed << "\nobject: " << in.object << "\n"
    << "scenes:\n  - name: advise\n    generate: scene.yaml\n    scenario: table\n"
    << "descriptors: " << list(descriptors) << "\nrefinements: " << list(refinements) << "\n"
    << "grid:\n  scale.length_factor: " << list(factors) << "\n"
    << "settings:\n  preprocess: {max_range_mm: " << num(in.max_range_mm)
    << (in.veil_angle_deg > 0 ? ", veil_angle_deg: " + num(in.veil_angle_deg) +
                                    "}   # time of flight: drop the mixed pixels at depth edges first\n"
                              : "}\n")
    << "thresholds: {table_translation_mm: " << num(in.translation_mm) << "}   # a quarter of the diameter\n"
    << "timeout_s: 300\n";
  return y.str();
}

// Area-weighted surface samples of a mesh (seeded).
std::vector<Vec3f> surface_samples(const Mesh& m, int n, uint64_t seed) {
  std::vector<double> cum;
  double total = 0;
  for (const auto& f : m.faces) {
    const Vec3f a = m.vertices[f[0]], b = m.vertices[f[1]], c = m.vertices[f[2]];
    total += 0.5 * (b - a).cross(c - a).norm();
    cum.push_back(total);
  }
  std::vector<Vec3f> out;
  if (!(total > 0)) return out;
  Rng rng(seed);
  for (int i = 0; i < n; ++i) {
    const size_t k = static_cast<size_t>(std::lower_bound(cum.begin(), cum.end(), rng.uniform() * total) - cum.begin());
    const auto& f = m.faces[std::min(k, m.faces.size() - 1)];
    double u = rng.uniform(), v = rng.uniform();
    if (u + v > 1) u = 1 - u, v = 1 - v;
    const Vec3f a = m.vertices[f[0]], b = m.vertices[f[1]], c = m.vertices[f[2]];
    out.push_back(a + static_cast<float>(u) * (b - a) + static_cast<float>(v) * (c - a));
  }
  return out;
}

}  // namespace

std::string symmetry_warning(const Mesh& mesh, uint64_t seed, double tolerance) {
  const std::vector<Vec3f> pts = surface_samples(mesh, 8000, seed);
  const std::vector<Vec3f> probes = surface_samples(mesh, 2000, seed + 1);
  if (pts.empty()) return "";
  const KdTree3 tree(pts);
  const double d = exact_diameter(mesh);
  const Vec3f centre = mesh.bounds().center();
  auto mean_distance = [&](const Eigen::Matrix3f& R) {
    double sum = 0;
    for (const Vec3f& p : probes) {
      float sq = 0;
      tree.nearest(R * (p - centre) + centre, &sq);
      sum += std::sqrt(sq);
    }
    return sum / static_cast<double>(probes.size());
  };
  // Other samples of the same surface are this far from the tree's: the
  // sampling's own distance, what a rotation onto itself also shows.
  const double floor = mean_distance(Eigen::Matrix3f::Identity());
  auto maps_onto_itself = [&](const Vec3& axis, double deg) {
    return mean_distance(axis_angle(axis, deg * M_PI / 180.0).cast<float>()) < 1.5 * floor + tolerance * d;
  };
  std::string found;
  const char* names[] = {"x", "y", "z"};
  for (int a = 0; a < 3; ++a) {
    Vec3 axis = Vec3::Zero();
    axis[a] = 1;
    bool continuous = true;
    for (double deg : {23.0, 61.0, 97.0, 137.0}) continuous = continuous && maps_onto_itself(axis, deg);
    const std::string ax = std::string("[") + (a == 0 ? "1, 0, 0" : a == 1 ? "0, 1, 0" : "0, 0, 1") + "]";
    if (continuous) {
      found += std::string("\n  every rotation about ") + names[a] + ": symmetries_continuous: [{axis: " + ax +
               ", offset: [0, 0, 0]}]";
      continue;
    }
    for (int k : {2, 3, 4, 6})
      if (maps_onto_itself(axis, 360.0 / k)) {
        found += std::string("\n  a 1/") + std::to_string(k) + " turn about " + names[a] +
                 ": symmetries_discrete (the " + std::to_string(k - 1) + " turns as 4x4 matrices)";
        break;
      }
  }
  if (found.empty()) return "";
  return "the mesh looks symmetric (its surface maps onto itself within " + num(tolerance * 100) +
         "% of the diameter) under" + found +
         "\nWithout that entry in a models.yaml (BOP models_info), poses equal up to the symmetry count as wrong "
         "and the robustness below is too low.";
}

AdviceInputs write_advice_inputs(const AdviseOptions& opt, const std::string& out_dir) {
  if (opt.scenario != "table") throw InputError("", "--scenario", "only 'table' is supported, got '" + opt.scenario + "'");
  ModelSpec spec;
  spec.scale = opt.mesh_scale;
  spec.up = opt.up;
  Mesh mesh = load_mesh(opt.mesh);  // InputError naming the file when missing or broken
  if (mesh.empty()) throw InputError(opt.mesh, "faces", "the mesh has no triangles");
  ModelRegistry::normalize(&mesh, spec);
  AdviceInputs in;
  in.object = object_name(opt.mesh);
  in.diameter_mm = exact_diameter(mesh);
  const double extent = mesh.bounds().diagonal().maxCoeff();
  if (!(in.diameter_mm > 0) || !std::isfinite(in.diameter_mm))
    throw InputError(opt.mesh, "vertices", "the mesh has no extent (all vertices at one point, or not finite)");
  const std::string warn = symmetry_warning(mesh, opt.seed);
  if (!warn.empty()) in.warnings.push_back(warn);

  // The camera 2.5-5 diameters away (the object fills about half to a quarter
  // of the image height of a 45-60 degree sensor), inside the sensor's range.
  const SensorProfile sensor = sensor_profile(opt.sensor);
  const double d = in.diameter_mm;
  const double lo = std::max(2.5 * d, sensor.min_range_mm + 0.75 * d);
  const double hi = std::max(lo, std::min(5.0 * d, sensor.max_range_mm - d));
  if (lo + 0.5 * d > sensor.max_range_mm)
    throw InputError(opt.mesh, "size", "a " + num(d) + " mm object does not fit in the " + opt.sensor +
                                           "'s range (" + num(sensor.max_range_mm) + " mm)");
  const double pixels = d * sensor.K.fx / lo;
  if (pixels < 20)
    throw InputError(opt.mesh, "size", "the object is " + num(d) + " mm across (its diameter): about " + num(pixels) +
                                           " pixels at the " + opt.sensor + "'s nearest distance of " + num(lo) +
                                           " mm, too small to recognize. Is the file in mm? (--mesh-scale)");
  in.max_range_mm = hi + 2 * d;
  in.translation_mm = 0.25 * d;
  in.veil_angle_deg = sensor.noise.model == "tof" ? 10.0 : 0.0;

  fs::create_directories(out_dir);
  atomic_write_text(out_dir + "/models.yaml", registry_yaml(opt, in.object, extent));
  std::ostringstream scene;
  scene << "# Written by `posebench advise`.\nscenario: table\ndescription: " << in.object << " with distractors of its size, "
        << opt.sensor << "\nscene_id: 1\nseed: " << opt.seed << "\nimages: " << opt.images << "\nsensor: " << opt.sensor
        << "\nregistry: models.yaml\ntarget: " << in.object
        << "\ntarget_upright_probability: 0.5\nmin_target_visib: 0.7\n"
        << "distractors: {pool: [box, cylinder, boletus], count: [2, 5], upright_probability: 0.7}\n"
        << "occlusion: none\ncamera: {distance_mm: [" << num(lo) << ", " << num(hi) << "], elevation_deg: [30, 70]}\n"
        << "table: {size_mm: " << num(std::max(4000.0, 30 * d)) << "}\n";
  atomic_write_text(out_dir + "/scene.yaml", scene.str());
  in.experiment = out_dir + "/experiment.yaml";
  atomic_write_text(in.experiment, experiment_yaml("advise_" + in.object, opt, in, opt.descriptors, opt.refinements,
                                                   opt.length_factors));
  return in;
}

std::vector<AdviceRow> rank_advice(const std::vector<TrialRecord>& records, double budget_ms) {
  struct Cell {
    int k = 0, n = 0;
    std::vector<double> t, r, ms;
  };
  std::map<std::tuple<std::string, std::string, double>, Cell> cells;
  for (const TrialRecord& rec : records) {
    const double f = rec.params.contains("scale.length_factor") ? rec.params["scale.length_factor"].get<double>() : 1.0;
    Cell& c = cells[{rec.descriptor, rec.refinement, f}];
    ++c.n;
    if (rec.times) c.ms.push_back(rec.times->total * 1000);
    if (rec.correct.value_or(false) && rec.errors) {
      ++c.k;
      c.t.push_back(rec.errors->translation_mm);
      c.r.push_back(rec.errors->rotation_deg);
    }
  }
  std::vector<AdviceRow> rows;
  for (auto& [key, c] : cells) {
    AdviceRow r;
    std::tie(r.descriptor, r.refinement, r.length_factor) = key;
    r.correct = wilson(c.k, c.n);
    r.median_translation_mm = c.t.empty() ? NAN : median(c.t);
    r.median_rotation_deg = c.r.empty() ? NAN : median(c.r);
    r.median_time_ms = c.ms.empty() ? NAN : median(c.ms);
    r.within_budget = !(budget_ms > 0) || r.median_time_ms <= budget_ms;
    rows.push_back(r);
  }
  std::stable_sort(rows.begin(), rows.end(), [](const AdviceRow& a, const AdviceRow& b) {
    if (a.within_budget != b.within_budget) return a.within_budget;
    if (a.correct.k != b.correct.k) return a.correct.k > b.correct.k;
    return a.median_time_ms < b.median_time_ms;
  });
  return rows;
}

std::string advice_table(const std::vector<AdviceRow>& rows, double budget_ms) {
  auto fixed = [](double v, int digits, const char* unit) {
    if (std::isnan(v)) return std::string("-");
    std::ostringstream o;
    o << std::fixed << std::setprecision(digits) << v << unit;
    return o.str();
  };
  std::ostringstream o;
  o << std::left << std::setw(6) << "rank" << std::setw(9) << "method" << std::setw(12) << "refinement" << std::setw(9)
    << "lengths" << std::setw(9) << "correct" << std::setw(15) << "95% interval" << std::setw(13) << "translation"
    << std::setw(11) << "rotation" << "time/image\n";
  int rank = 0;
  for (const AdviceRow& r : rows) {
    o << std::setw(6) << ++rank << std::setw(9) << r.descriptor << std::setw(12) << r.refinement << std::setw(9)
      << ("x" + num(r.length_factor)) << std::setw(9) << (std::to_string(r.correct.k) + "/" + std::to_string(r.correct.n))
      << std::setw(15) << ("[" + fixed(r.correct.lo, 2, "") + ", " + fixed(r.correct.hi, 2, "") + "]") << std::setw(13)
      << fixed(r.median_translation_mm, 1, " mm") << std::setw(11) << fixed(r.median_rotation_deg, 2, " deg")
      << fixed(r.median_time_ms, 0, " ms") << (r.within_budget ? "" : "  (over the " + num(budget_ms) + " ms budget)")
      << "\n";
  }
  o << "(translation and rotation: medians over the correct images; time: median online time per image, one "
       "worker)\n";
  return o.str();
}

std::string best_experiment_yaml(const AdviceRow& row, const AdviseOptions& opt, const AdviceInputs& in) {
  return experiment_yaml("advise_" + in.object + "_best", opt, in, {row.descriptor}, {row.refinement},
                         {row.length_factor});
}

}  // namespace pb
