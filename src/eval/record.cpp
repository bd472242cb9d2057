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
// f(key, member, when the key is required)

enum class Req {
  always,    // in every record
  optional,  // when the trial got that far
  when_ok,   // in every record with status ok
  when_gt,   // in every record with status ok and ground truth (`gt`): the judged ones
};
constexpr Req kAlways = Req::always, kOptional = Req::optional, kWhenOk = Req::when_ok, kWhenGt = Req::when_gt;

template <typename S, typename F>
void fields(S& r, F& f, PoseRecord*) {
  f("R", r.R, kAlways);
  f("t", r.t, kAlways);
}
template <typename S, typename F>
void fields(S& r, F& f, StageTimesRecord*) {
  StageTimes::each([&](const char* name, double StageTimes::*stage) { f(name, r.stages.*stage, kAlways); });
  f("total", r.total, kAlways);
}
template <typename S, typename F>
void fields(S& r, F& f, ThesisErrorsRecord*) {
  f("translation_mm", r.translation_mm, kAlways);
  f("rotation_1mpq", r.rotation_1mpq, kAlways);
  f("rotation_deg", r.rotation_deg, kAlways);
  f("symmetry", r.symmetry, kAlways);
  f("translation_mm_plain", r.translation_mm_plain, kAlways);
  f("rotation_1mpq_plain", r.rotation_1mpq_plain, kAlways);
}
template <typename S, typename F>
void fields(S& r, F& f, BopErrorsRecord*) {
  f("mssd_mm", r.mssd_mm, kAlways);
  f("mspd_px", r.mspd_px, kAlways);
  f("vsd", r.vsd, kAlways);
  f("diameter", r.diameter, kAlways);
  f("image_width", r.image_width, kAlways);
}
template <typename S, typename F>
void fields(S& r, F& f, JudgementRecord*) {
  f("correct", r.correct, kAlways);
  f("translation_mm", r.translation_mm, kAlways);
  f("rotation_1mpq", r.rotation_1mpq, kAlways);
}
template <typename S, typename F>
void fields(S& r, F& f, InstanceRecord*) {
  f("estimate", r.estimate, kAlways);
  f("score", r.score, kAlways);
  f("inliers", r.inliers, kAlways);
  f("correct", r.correct, kOptional);
}
template <typename S, typename F>
void fields(S& r, F& f, TrialRecord*) {
  f("key", r.key, kAlways);
  f("scene", r.scene, kAlways);
  f("scenario", r.scenario, kAlways);
  f("dataset", r.dataset, kAlways);
  f("split", r.split, kAlways);
  f("scene_id", r.scene_id, kAlways);
  f("im_id", r.im_id, kAlways);
  f("descriptor", r.descriptor, kAlways);
  f("refinement", r.refinement, kAlways);
  f("inst_count", r.inst_count, kOptional);
  f("params", r.params, kAlways);
  f("added_noise_mm", r.added_noise_mm, kAlways);
  f("settings", r.settings, kAlways);
  f("seed", r.seed, kAlways);
  f("status", r.status, kAlways);
  f("correct", r.correct, kWhenGt);
  f("wall_s", r.wall_s, kWhenOk);
  f("message", r.message, kOptional);
  f("obj_id", r.obj_id, kWhenOk);
  f("settings_resolved", r.settings_resolved, kWhenOk);
  f("train_s", r.train_s, kWhenOk);
  f("train_from_cache", r.train_from_cache, kWhenOk);
  f("times", r.times, kWhenOk);
  f("hypotheses", r.hypotheses, kWhenOk);
  f("correct_rank", r.correct_rank, kOptional);
  f("init", r.init, kOptional);
  f("estimate", r.estimate, kWhenOk);
  f("instances", r.instances, kOptional);
  f("score", r.score, kWhenOk);
  f("inliers", r.inliers, kWhenOk);
  f("gt", r.gt, kOptional);
  f("visib_fract", r.visib_fract, kOptional);
  f("errors", r.errors, kWhenGt);
  f("bop", r.bop, kWhenGt);
  f("judgements", r.judgements, kOptional);
}

template <typename S>
constexpr bool is_record_struct = std::is_same_v<S, PoseRecord> || std::is_same_v<S, StageTimesRecord> ||
                                  std::is_same_v<S, ThesisErrorsRecord> || std::is_same_v<S, BopErrorsRecord> ||
                                  std::is_same_v<S, JudgementRecord> || std::is_same_v<S, InstanceRecord> ||
                                  std::is_same_v<S, TrialRecord>;
template <typename T>
constexpr bool is_struct_vector = false;
template <typename T>
constexpr bool is_struct_vector<std::vector<T>> = is_record_struct<T>;

// --- writing ---------------------------------------------------------------

template <typename T>
nlohmann::json write_value(const T& v);

template <typename S>
nlohmann::json write_struct(const S& s) {
  nlohmann::json j = nlohmann::json::object();
  auto f = [&](const char* key, const auto& member, Req) {
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
  } else if constexpr (is_struct_vector<T>) {
    nlohmann::json j = nlohmann::json::array();
    for (const auto& x : v) j.push_back(write_value(x));
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

// Whether a key of requirement `req` must be in the object `j` (a record:
// when_ok and when_gt look at its status and ground truth).
bool needed(Req req, const nlohmann::json& j) {
  if (req == Req::always) return true;
  if (req == Req::optional) return false;
  const auto st = j.find("status");
  const bool ok = st != j.end() && st->is_string() && st->get<std::string>() == "ok";
  return ok && (req == Req::when_ok || j.contains("gt"));
}

std::string required_when(Req req) {
  return req == Req::when_ok ? " (required with status ok)"
         : req == Req::when_gt ? " (required with status ok and gt)"
                               : "";
}

template <typename S>
void read_struct(const nlohmann::json& j, S& s, const std::string& path, const Where& w) {
  if (!j.is_object()) w.fail(path.empty() ? "(record)" : path, "expected a JSON object");
  std::vector<std::string> known;
  auto list = [&](const char* key, auto&, Req) { known.push_back(key); };
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
  auto f = [&](const char* key, auto& member, Req req) {
    using M = std::decay_t<decltype(member)>;
    const std::string p = path.empty() ? key : path + "." + key;
    const auto it = j.find(key);
    if (it == j.end()) {
      if (needed(req, j)) w.fail(p, "missing required key" + required_when(req));
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
  } else if constexpr (is_struct_vector<T>) {
    if (!j.is_array()) w.fail(path, "expected a JSON list");
    v.resize(j.size());
    for (size_t i = 0; i < j.size(); ++i) read_value(j[i], v[i], path + "[" + std::to_string(i) + "]", w);
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
  auto f = [&](const char* key, auto& member, Req req) {
    using M = std::decay_t<decltype(member)>;
    nlohmann::json e;
    if constexpr (is_optional<M>::value)
      e = schema_of<typename M::value_type>();
    else
      e = schema_of<M>();
    e["required"] = req == Req::always     ? nlohmann::json(true)
                    : req == Req::optional ? nlohmann::json(false)
                    : req == Req::when_ok  ? nlohmann::json("when_ok")
                                           : nlohmann::json("when_gt");
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
  } else if constexpr (is_struct_vector<T>) {
    return {{"type", "array"}, {"items", schema_of<typename T::value_type>()}};
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
  s["notes"] = {"required: true = in every record; \"when_ok\" = in every record with status ok; \"when_gt\" = "
                "in every record with status ok and a gt (the judged ones); false = when the trial got that far "
                "(message, init with registration_only, gt and visib_fract when the image has the object, "
                "judgements when the experiment declares them, inst_count and instances for BOP test targets)",
                "a trial whose worker crashed, timed out or ran out of memory (status error, timeout or "
                "out_of_memory) has the always-required "
                "keys, message and correct = false only",
                "type object with \"fields\": those keys only; with \"values\": any keys, each value as given; "
                "with \"free\": true: any keys and values",
                "poses are {R: 9 numbers row-major, t: 3 numbers in mm}, T_cam_model"};
  return s;
}

}  // namespace pb
