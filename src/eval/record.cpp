// TrialRecord <-> JSON from one field list per struct (the `fields`
// functions below): writing, strict reading and the schema all derive from
// it, so a key is spelt once.
#include "eval/record.h"

#include <algorithm>
#include <set>
#include <type_traits>

#include "core/error.h"

namespace pb {

namespace {

template <typename T>
struct is_optional : std::false_type {};
template <typename T>
struct is_optional<std::optional<T>> : std::true_type {};
template <typename T>
struct is_std_array : std::false_type {};
template <typename T, size_t N>
struct is_std_array<std::array<T, N>> : std::true_type {};
template <typename T>
struct is_map : std::false_type {};
template <typename T>
struct is_map<std::map<std::string, T>> : std::true_type {};

// --- the field lists -------------------------------------------------------
// f(key, member, required?)

template <typename S, typename F>
void fields(S& r, F& f, PoseRecord*) {
  f("R", r.R, true);
  f("t", r.t, true);
}
template <typename S, typename F>
void fields(S& r, F& f, StageTimesRecord*) {
  f("preprocess", r.preprocess, true);
  f("describe", r.describe, true);
  f("match", r.match, true);
  f("group", r.group, true);
  f("initial_pose", r.initial_pose, true);
  f("refine", r.refine, true);
  f("verify", r.verify, true);
  f("total", r.total, true);
}
template <typename S, typename F>
void fields(S& r, F& f, ThesisErrorsRecord*) {
  f("translation_mm", r.translation_mm, true);
  f("rotation_1mpq", r.rotation_1mpq, true);
  f("rotation_deg", r.rotation_deg, true);
  f("symmetry", r.symmetry, true);
  f("translation_mm_plain", r.translation_mm_plain, true);
  f("rotation_1mpq_plain", r.rotation_1mpq_plain, true);
}
template <typename S, typename F>
void fields(S& r, F& f, BopErrorsRecord*) {
  f("mssd_mm", r.mssd_mm, true);
  f("mspd_px", r.mspd_px, true);
  f("vsd", r.vsd, true);
  f("diameter", r.diameter, true);
  f("image_width", r.image_width, true);
}
template <typename S, typename F>
void fields(S& r, F& f, JudgementRecord*) {
  f("correct", r.correct, true);
  f("translation_mm", r.translation_mm, true);
  f("rotation_1mpq", r.rotation_1mpq, true);
}
template <typename S, typename F>
void fields(S& r, F& f, TrialRecord*) {
  f("key", r.key, true);
  f("scene", r.scene, true);
  f("scenario", r.scenario, true);
  f("dataset", r.dataset, true);
  f("split", r.split, true);
  f("scene_id", r.scene_id, true);
  f("im_id", r.im_id, true);
  f("descriptor", r.descriptor, true);
  f("refinement", r.refinement, true);
  f("params", r.params, true);
  f("added_noise_mm", r.added_noise_mm, true);
  f("settings", r.settings, true);
  f("seed", r.seed, true);
  f("status", r.status, true);
  f("correct", r.correct, true);
  f("wall_s", r.wall_s, true);
  f("message", r.message, false);
  f("obj_id", r.obj_id, false);
  f("settings_resolved", r.settings_resolved, false);
  f("train_s", r.train_s, false);
  f("train_from_cache", r.train_from_cache, false);
  f("times", r.times, false);
  f("hypotheses", r.hypotheses, false);
  f("init", r.init, false);
  f("estimate", r.estimate, false);
  f("score", r.score, false);
  f("inliers", r.inliers, false);
  f("gt", r.gt, false);
  f("visib_fract", r.visib_fract, false);
  f("errors", r.errors, false);
  f("bop", r.bop, false);
  f("judgements", r.judgements, false);
}

template <typename S>
constexpr bool is_record_struct = std::is_same_v<S, PoseRecord> || std::is_same_v<S, StageTimesRecord> ||
                                  std::is_same_v<S, ThesisErrorsRecord> || std::is_same_v<S, BopErrorsRecord> ||
                                  std::is_same_v<S, JudgementRecord> || std::is_same_v<S, TrialRecord>;

// --- writing ---------------------------------------------------------------

template <typename T>
nlohmann::json write_value(const T& v);

template <typename S>
nlohmann::json write_struct(const S& s) {
  nlohmann::json j = nlohmann::json::object();
  auto f = [&](const char* key, const auto& member, bool) {
    using M = std::decay_t<decltype(member)>;
    if constexpr (is_optional<M>::value) {
      if (member) j[key] = write_value(*member);
    } else if constexpr (is_map<M>::value) {
      if (!member.empty()) j[key] = write_value(member);
    } else {
      j[key] = write_value(member);
    }
  };
  fields(s, f, static_cast<S*>(nullptr));
  return j;
}

template <typename T>
nlohmann::json write_value(const T& v) {
  if constexpr (is_record_struct<T>) {
    return write_struct(v);
  } else if constexpr (is_map<T>::value) {
    nlohmann::json j = nlohmann::json::object();
    for (const auto& [k, x] : v) j[k] = write_value(x);
    return j;
  } else {
    return nlohmann::json(v);
  }
}

// --- strict reading --------------------------------------------------------

struct Where {
  const std::string& file;
  int line;
  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    throw InputError(file, "line " + std::to_string(line) + ": " + key,
                     what + " (record at line " + std::to_string(line) + ", key '" + key + "')");
  }
};

template <typename T>
void read_value(const nlohmann::json& j, T& v, const std::string& path, const Where& w);

// Levenshtein distance, for "did you mean" on a misspelt key.
size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (size_t j = 1; j <= b.size(); ++j)
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

template <typename S>
void read_struct(const nlohmann::json& j, S& s, const std::string& path, const Where& w) {
  if (!j.is_object()) w.fail(path.empty() ? "(record)" : path, "expected a JSON object");
  std::vector<std::string> known;
  auto list = [&](const char* key, auto&, bool) { known.push_back(key); };
  fields(s, list, static_cast<S*>(nullptr));
  // Unknown keys first: a misspelt key is named as such, not as the
  // required key it should have been.
  for (auto it = j.begin(); it != j.end(); ++it) {
    if (std::find(known.begin(), known.end(), it.key()) != known.end()) continue;
    std::string hint;
    for (const auto& k : known)
      if (edit_distance(k, it.key()) <= 2) hint = " (did you mean '" + k + "'?)";
    w.fail(path.empty() ? it.key() : path + "." + it.key(), "unknown key" + hint);
  }
  auto f = [&](const char* key, auto& member, bool required) {
    using M = std::decay_t<decltype(member)>;
    const std::string p = path.empty() ? key : path + "." + key;
    const auto it = j.find(key);
    if (it == j.end()) {
      if (required) w.fail(p, "missing required key");
      return;
    }
    if constexpr (is_optional<M>::value) {
      member.emplace();
      read_value(*it, *member, p, w);
    } else {
      read_value(*it, member, p, w);
    }
  };
  fields(s, f, static_cast<S*>(nullptr));
}

template <typename T>
void read_value(const nlohmann::json& j, T& v, const std::string& path, const Where& w) {
  if constexpr (is_record_struct<T>) {
    read_struct(j, v, path, w);
  } else if constexpr (is_map<T>::value) {
    if (!j.is_object()) w.fail(path, "expected a JSON object");
    for (auto it = j.begin(); it != j.end(); ++it) read_value(it.value(), v[it.key()], path + "." + it.key(), w);
  } else if constexpr (std::is_same_v<T, nlohmann::json>) {
    if (!j.is_object()) w.fail(path, "expected a JSON object");
    v = j;
  } else {
    using E = T;
    const bool ok = std::is_same_v<E, bool>          ? j.is_boolean()
                    : std::is_same_v<E, std::string> ? j.is_string()
                    : std::is_integral_v<E>          ? j.is_number_integer()
                    : std::is_floating_point_v<E>    ? j.is_number()
                                                     : j.is_array();
    if (!ok) w.fail(path, "wrong type (" + std::string(j.type_name()) + ")");
    if constexpr (is_std_array<E>::value)
      if (j.size() != std::tuple_size<E>::value)
        w.fail(path, "expected " + std::to_string(std::tuple_size<E>::value) + " numbers");
    try {
      v = j.get<T>();
    } catch (const nlohmann::json::exception& e) {
      w.fail(path, std::string("wrong value: ") + e.what());
    }
  }
}

// --- schema ----------------------------------------------------------------

template <typename T>
nlohmann::json schema_of();

template <typename S>
nlohmann::json schema_struct() {
  nlohmann::json fs = nlohmann::json::object();
  S s{};
  auto f = [&](const char* key, auto& member, bool required) {
    using M = std::decay_t<decltype(member)>;
    nlohmann::json e;
    if constexpr (is_optional<M>::value)
      e = schema_of<typename M::value_type>();
    else
      e = schema_of<M>();
    e["required"] = required;
    fs[key] = e;
  };
  fields(s, f, static_cast<S*>(nullptr));
  return {{"type", "object"}, {"fields", fs}};
}

template <typename T>
nlohmann::json schema_of() {
  if constexpr (is_record_struct<T>) {
    return schema_struct<T>();
  } else if constexpr (is_map<T>::value) {
    nlohmann::json e = schema_of<typename T::mapped_type>();
    return {{"type", "object"}, {"values", e}};
  } else if constexpr (std::is_same_v<T, nlohmann::json>) {
    return {{"type", "object"}, {"free", true}};
  } else if constexpr (std::is_same_v<T, bool>) {
    return {{"type", "boolean"}};
  } else if constexpr (std::is_same_v<T, std::string>) {
    return {{"type", "string"}};
  } else if constexpr (std::is_integral_v<T>) {
    return {{"type", "integer"}};
  } else if constexpr (std::is_floating_point_v<T>) {
    return {{"type", "number"}};
  } else {
    return {{"type", "array"}};
  }
}

}  // namespace

PoseRecord PoseRecord::from(const Pose& T) {
  PoseRecord p;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) p.R[static_cast<size_t>(3 * r + c)] = T.R(r, c);
  for (int r = 0; r < 3; ++r) p.t[static_cast<size_t>(r)] = T.t[r];
  return p;
}

Pose PoseRecord::pose() const {
  Pose T;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) T.R(r, c) = R[static_cast<size_t>(3 * r + c)];
  for (int r = 0; r < 3; ++r) T.t[r] = t[static_cast<size_t>(r)];
  return T;
}

void to_json(nlohmann::json& j, const TrialRecord& r) { j = write_struct(r); }

TrialRecord record_from_json(const nlohmann::json& j, const std::string& file, int line) {
  TrialRecord r;
  read_struct(j, r, "", Where{file, line});
  return r;
}

nlohmann::json record_schema() {
  nlohmann::json s = schema_struct<TrialRecord>();
  s["notes"] = {"required: present in every record; the others are present when the trial got that far "
                "(estimate and score with status ok, errors and bop with status ok and ground truth, judgements "
                "when the experiment declares them)",
                "poses are {R: 9 numbers row-major, t: 3 numbers in mm}, T_cam_model"};
  return s;
}

}  // namespace pb
