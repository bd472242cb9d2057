#include "runner/runner.h"

#include "render/sensor.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <deque>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <iostream>
#include <memory>
#include <sstream>
#include <unordered_set>
#include <vector>

#include "core/error.h"
#include "core/log.h"
#include "core/file_lock.h"
#include "core/timer.h"
#include "core/yaml.h"
#include "io/png.h"
#include "runner/merge.h"
#include "runner/pool.h"
#include "runner/store.h"
#include "runner/trial.h"
#include "scenes/generator.h"

namespace fs = std::filesystem;

namespace pb {

// The generator configs are YAML; overrides merge at the JSON level and the
// result is written as JSON (a YAML subset) for the generator to read.
static nlohmann::json yaml_to_json_file(const std::string& path) { return YamlNode::load_file(path).json(); }

static int run_command(const std::vector<std::string>& args, const std::string& log_path) {
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("fork failed");
  if (pid == 0) {
    const int fd = ::open(log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) {
      dup2(fd, 1);
      dup2(fd, 2);
    }
    std::vector<char*> argv;
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execv(argv[0], argv.data());
    _exit(127);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

// Makes the scene set scenes_dir/STEM once, whatever the number of runs
// asking for it: nothing when `complete` says it is there; else, under
// STEM.lock, `command` (its output in STEM.log), whose failure is an
// InputError(file, field, what + the log).
static void make_scene_set_once(const RunOptions& opt, const std::string& stem, const std::function<bool()>& complete,
                                const std::function<std::vector<std::string>()>& command, const std::string& file,
                                const std::string& field, const std::string& what) {
  if (complete()) return;
  fs::create_directories(opt.scenes_dir);
  const FileLock lock = FileLock::acquire((fs::path(opt.scenes_dir) / (stem + ".lock")).string());
  if (complete()) return;  // another process made it while this one waited
  const std::string log = (fs::path(opt.scenes_dir) / (stem + ".log")).string();
  const int rc = run_command(command(), log);
  if (rc != 0) {
    std::ifstream in(log);
    std::stringstream ss;
    ss << in.rdbuf();
    throw InputError(file, field, what + " (exit " + std::to_string(rc) + "): " + ss.str());
  }
}

// A `clouds:` scene set: `posebench import-clouds` into
// scenes_dir/NAME_HASH (HASH of the clouds' bytes, their options and the
// object).
static void import_scene_clouds(SceneSource& src, const ExperimentConfig& cfg, const RunOptions& opt) {
  std::string key = cfg.object + "\n" + src.cloud.dump();
  for (const auto& c : src.clouds) {
    std::ifstream in(c, std::ios::binary);
    key += "\n" + hash_hex(std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>()));
  }
  const std::string stem = src.name + "_" + hash_hex(key).substr(0, 8);
  const fs::path dir = fs::path(opt.scenes_dir) / stem;
  src.dataset = dir.string();
  const auto command = [&] {
    std::vector<std::string> args{opt.binary, "import-clouds", "--out", dir.string(), "--object", cfg.object};
    for (const char* k : {"units", "intrinsics", "camera"}) {
      if (!src.cloud.contains(k)) continue;
      std::string v;
      if (src.cloud[k].is_array())  // intrinsics: [fx, fy, cx, cy(, width, height)]
        for (const auto& x : src.cloud[k]) v += (v.empty() ? "" : ",") + (x.is_string() ? x.get<std::string>() : x.dump());
      else
        v = src.cloud[k].is_string() ? src.cloud[k].get<std::string>() : src.cloud[k].dump();
      args.insert(args.end(), {std::string("--") + k, v});
    }
    args.insert(args.end(), src.clouds.begin(), src.clouds.end());
    log_event(LogLevel::info, "import_clouds", {{"scene", src.name}, {"clouds", src.clouds.size()}, {"dataset", dir.string()}});
    return args;
  };
  make_scene_set_once(opt, stem, [&] { return fs::exists(dir / "posebench_clouds.json"); }, command, cfg.file,
                      "scenes." + src.name + ".clouds", "importing the clouds failed");
}

// A twin scene set (SceneSource::twin_sensor) made by `posebench twin` from
// its real set's dataset, once per real set, sensor, seed and twin version.
static void make_twin(SceneSource& src, const ExperimentConfig& cfg, const RunOptions& opt) {
  const auto real = std::find_if(cfg.scenes.begin(), cfg.scenes.end(),
                                 [&](const SceneSource& x) { return x.name == src.twin_of; });
  const std::string real_root = fs::absolute(real->dataset).lexically_normal().string();
  std::string sensor = src.twin_sensor;
  if (is_profile_file(sensor)) sensor = fs::absolute(sensor).lexically_normal().string();
  // One twin per real set, sensor model (what it resolves to, not its name:
  // a built-in's defaults may change), seed and background.
  const SensorProfile prof = parse_sensor(YamlNode::load_string(sensor, "scenes." + src.name + ".twin.sensor"));
  const std::string identity = real_root + "#" + real->split + "#" + std::to_string(src.twin_seed) + "#" +
                               (src.twin_keep_background ? "bg" : "") + "#twin_version=1#" + prof.name + "#" +
                               noise_json(prof.noise).dump() + "#" + std::to_string(prof.min_range_mm) + "," +
                               std::to_string(prof.max_range_mm);
  const std::string stem = src.name + "_" + hash_hex(identity).substr(0, 8);
  const fs::path dir = fs::path(opt.scenes_dir) / stem;
  src.dataset = dir.string();
  const auto command = [&]() -> std::vector<std::string> {
    log_event(LogLevel::info, "make_twin", {{"scene", src.name}, {"of", src.twin_of}, {"dataset", dir.string()}});
    std::vector<std::string> args{opt.binary, "twin",    real_root, "--sensor", sensor, "--out", dir.string(),
                                  "--split",  real->split, "--seed", std::to_string(src.twin_seed)};
    if (src.twin_keep_background) args.push_back("--keep-background");
    return args;
  };
  make_scene_set_once(opt, stem, [&] { return fs::exists(dir / "posebench_twin.json"); }, command, cfg.file,
                      "scenes." + src.name + ".twin", "making the twin failed");
}

void prepare_scenes(ExperimentConfig& cfg, const RunOptions& opt) {
  for (auto& src : cfg.scenes) {
    if (!src.twin_sensor.empty()) make_twin(src, cfg, opt);
    if (!src.clouds.empty()) import_scene_clouds(src, cfg, opt);
    if (src.generate.empty()) continue;
    nlohmann::json gen = yaml_to_json_file(src.generate);
    gen.merge_patch(src.generator_overrides);  // sections merge key by key: {warehouse: {wall: true}}
    // The copy lives in scenes_dir: make a relative registry path absolute
    // against the original config's folder.
    if (gen.contains("registry") && gen["registry"].is_string() &&
        fs::path(gen["registry"].get<std::string>()).is_relative())
      gen["registry"] = fs::absolute(fs::path(src.generate).parent_path() / gen["registry"].get<std::string>())
                            .lexically_normal()
                            .string();
    // One set per config and generator version (version 1 keeps the names
    // of the sets made before the version existed).
    const std::string versioned =
        gen.dump() + (kSceneSetVersion > 1 ? "#scene_set_version=" + std::to_string(kSceneSetVersion) : "");
    const std::string stem = src.name + "_" + hash_hex(versioned).substr(0, 8);
    const fs::path dir = fs::path(opt.scenes_dir) / stem;
    src.dataset = dir.string();
    const auto command = [&]() -> std::vector<std::string> {
      const fs::path cfg_path = fs::path(opt.scenes_dir) / (stem + ".config.json");
      atomic_write_text(cfg_path.string(), gen.dump(2) + "\n");
      log_event(LogLevel::info, "generate_scenes", {{"scene", src.name}, {"dataset", dir.string()}});
      return {opt.binary, "generate", cfg_path.string(), "--out", dir.string()};
    };
    make_scene_set_once(
        opt, stem, [&] { return fs::exists(dir / "models" / "models_info.json") && fs::exists(dir / "camera.json"); },
        command, src.generate, "scenes." + src.name, "scene generation failed");
  }
}

namespace {

std::string fmt_duration(double s) {
  if (!std::isfinite(s) || s < 0) return "?";
  char buf[32];
  const long t = static_cast<long>(s + 0.5);
  if (t >= 3600)
    std::snprintf(buf, sizeof buf, "%ldh%02ldm", t / 3600, (t / 60) % 60);
  else
    std::snprintf(buf, sizeof buf, "%ldm%02lds", t / 60, t % 60);
  return buf;
}

// Progress on stderr: a bar with ETA on a terminal, a line every 10 s otherwise.
class Progress {
 public:
  Progress(bool quiet, size_t to_run) : quiet_(quiet), to_run_(to_run), tty_(isatty(2)) {}
  void update(const RunSummary& sum, bool final) {
    if (quiet_) return;
    const double el = timer_.seconds();
    const double frac = to_run_ ? static_cast<double>(sum.ran) / to_run_ : 1.0;
    const double eta = sum.ran ? el / sum.ran * (to_run_ - sum.ran) : NAN;
    char line[256];
    if (tty_) {
      const int width = 30, filled = static_cast<int>(frac * width);
      std::string bar(filled, '#');
      bar += std::string(width - filled, '.');
      std::snprintf(line, sizeof line, "\r[%s] %zu/%zu %3.0f%%  elapsed %s  ETA %s  ok %zu none %zu err %zu tmo %zu ",
                    bar.c_str(), sum.ran, to_run_, 100 * frac, fmt_duration(el).c_str(),
                    fmt_duration(eta).c_str(), sum.ok, sum.no_hypothesis, sum.errors, sum.timeouts);
      std::cerr << line << (final ? "\n" : "") << std::flush;
    } else if (final || last_print_.seconds() > 10) {  // not a terminal: a log line every 10 s
      log_event(LogLevel::info, "progress",
                {{"ran", sum.ran}, {"of", to_run_}, {"elapsed", fmt_duration(el)}, {"eta", fmt_duration(eta)},
                 {"ok", sum.ok}, {"no_hypothesis", sum.no_hypothesis}, {"error", sum.errors}, {"timeout", sum.timeouts}});
      last_print_.reset();
    }
  }

 private:
  bool quiet_;
  size_t to_run_;
  bool tty_;
  Timer timer_, last_print_;
};

void count(const TrialRecord& rec, RunSummary& sum) {
  ++sum.ran;
  if (rec.status == "ok") ++sum.ok;
  else if (rec.status == "no_hypothesis") ++sum.no_hypothesis;
  else if (rec.status == "timeout") ++sum.timeouts;
  else if (rec.status == "out_of_memory") ++sum.out_of_memory;
  else ++sum.errors;
}

std::string utc_now() {
  const std::time_t t = std::time(nullptr);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
  return buf;
}

double load15() {
  std::ifstream in("/proc/loadavg");
  double a = NAN, b = NAN, c = NAN;
  in >> a >> b >> c;
  return c;
}

}  // namespace

nlohmann::json summary_json(const RunSummary& s) {
  nlohmann::json j = {{"started", s.started},
          {"wall_s", s.seconds},
          {"total", s.total},
          {"already_recorded", s.already_done},
          {"ran", s.ran},
          {"status_counts", {{"ok", s.ok}, {"no_hypothesis", s.no_hypothesis}, {"error", s.errors},
                             {"timeout", s.timeouts}, {"out_of_memory", s.out_of_memory}}},
          {"jobs", s.jobs},
          {"omp_threads", s.omp_threads},
          {"load15_end", std::isfinite(s.load15_end) ? nlohmann::json(s.load15_end) : nlohmann::json(nullptr)},
          {"host_cores", s.host_cores}};
  if (!s.shard.empty()) j["shard"] = s.shard;
  return j;
}

RunSummary run_experiment(ExperimentConfig cfg, const RunOptions& opt) {
  RunSummary sum;
  sum.started = utc_now();
  Timer timer;
  const std::string out = opt.out_dir.empty() ? "results/" + cfg.name : opt.out_dir;
  // Guard the folder before doing anything expensive, but create it only
  // once the scenes and trials are known to be valid.
  ResultStore::check(out, cfg.hash);
  prepare_scenes(cfg, opt);
  const std::vector<Trial> trials = expand_trials(cfg);
  std::vector<std::string> keys;
  for (const Trial& t : trials) keys.push_back(t.key);
  if (!opt.shard.active() && !ResultStore::shard_record_files(out).empty()) {
    ResultStore::write_trial_list(out, cfg.hash, keys);
    const MergeReport m = merge_results(out);
    log_event(LogLevel::info, "merge_shards", {{"records", m.records}, {"into", out + "/records.jsonl"}});
  }
  ResultStore store(out, cfg.canonical, cfg.hash, opt.shard.active() ? opt.shard.name() : "");
  ResultStore::write_trial_list(out, cfg.hash, keys);
  // A shard skips what is recorded anywhere in OUT: its own earlier records
  // (the store), a merged run's, another shard's (also of another N).
  std::unordered_set<std::string> done_elsewhere;
  if (opt.shard.active()) {
    std::vector<std::string> files = ResultStore::shard_record_files(out);
    files.push_back((fs::path(out) / "records.jsonl").string());
    for (const auto& f : files)
      if (f != store.records_path())
        for (const auto& r : ResultStore::read_file(f)) done_elsewhere.insert(r.key);
  }
  const std::vector<bool> mine = shard_membership(keys, opt.shard);
  sum.shard = opt.shard.active() ? opt.shard.label() : "";
  sum.jobs = opt.jobs;
  sum.host_cores = static_cast<int>(sysconf(_SC_NPROCESSORS_ONLN));
  sum.omp_threads = omp_threads_per_worker(opt.jobs, sum.host_cores);

  std::vector<TrialRecord> inputs;
  std::deque<long> pending;
  for (long i = 0; i < static_cast<long>(trials.size()); ++i) {
    const auto u = static_cast<size_t>(i);
    inputs.push_back(trial_record(trials[u]));
    if (!mine[u]) continue;
    ++sum.total;
    if (!store.has(keys[u]) && !done_elsewhere.count(keys[u])) pending.push_back(i);
  }
  sum.already_done = sum.total - pending.size();
  if (sum.already_done)
    log_event(LogLevel::info, "resume", {{"recorded", sum.already_done}, {"trials", sum.total}});
  if (!pending.empty()) {
    PoolOptions po;
    po.binary = opt.binary;
    po.context = context_json(cfg, opt.cache_dir).dump();
    po.log_path = store.own_file("workers", "log");
    po.jobs = opt.jobs;
    po.omp_threads = sum.omp_threads;
    po.timeout_s = cfg.timeout_s;
    po.memory_limit_mb = opt.memory_limit_mb;
    if (opt.memory_limit_mb > 0 && !kMemoryLimitApplies)
      log_event(LogLevel::warn, "memory_limit_not_applied",
                {{"why", "AddressSanitizer reserves terabytes of address space: RLIMIT_AS would end every worker"}});
    Progress progress(opt.quiet, pending.size());
    run_in_workers(po, inputs, pending, [&](long, const TrialRecord& rec) {
      store.append(rec);
      count(rec, sum);
      if (log_enabled(LogLevel::debug)) {
        nlohmann::ordered_json f = {{"key", rec.key}, {"status", rec.status}};
        if (rec.correct) f["correct"] = *rec.correct;
        if (rec.times) f["total_s"] = rec.times->total;
        if (rec.message) f["message"] = *rec.message;
        log_event(LogLevel::debug, "trial", f);
      }
      progress.update(sum, false);
    });
    progress.update(sum, true);
  }
  sum.seconds = timer.seconds();
  sum.load15_end = load15();
  if (sum.ran > 0) store.append_run(summary_json(sum));
  return sum;
}

namespace {

// For testing the runner only (documented in docs/testing.md, "Kills and injected faults"):
// POSEBENCH_INJECT_FAULT="KIND:TEXT[;KIND:TEXT...]" makes a worker fail on
// every trial whose key contains TEXT: segfault (SIGSEGV), abort, exit (exit
// code 3), hang (sleeps until the trial's time-out) or oom (allocates until
// an allocation fails; only under a memory limit).
void inject_fault(const std::string& key) {
  const char* env = std::getenv("POSEBENCH_INJECT_FAULT");
  if (!env || !*env) return;
  std::stringstream spec(env);
  std::string item;
  while (std::getline(spec, item, ';')) {
    const size_t colon = item.find(':');
    if (colon == std::string::npos || key.find(item.substr(colon + 1)) == std::string::npos) continue;
    const std::string kind = item.substr(0, colon);
    log_event(LogLevel::warn, "injected_fault", {{"fault", kind}, {"key", key}});
    if (kind == "segfault") raise(SIGSEGV);
    if (kind == "abort") std::abort();
    if (kind == "exit") _exit(3);
    if (kind == "hang")
      for (;;) pause();
    if (kind == "oom") {
      rlimit lim{};
      if (getrlimit(RLIMIT_AS, &lim) != 0 || lim.rlim_cur == RLIM_INFINITY)
        throw std::runtime_error("injected fault 'oom' needs a memory limit (run --memory-limit-mb)");
      // Address space runs out at the limit (RLIMIT_AS) whether or not the
      // pages are written: one byte each keeps the blocks in use without
      // writing a gigabyte first (which, on a loaded machine, took longer
      // than the tests' 3 s trial limit and ended as a timeout).
      std::vector<std::unique_ptr<char[]>> hog;
      for (;;) {
        hog.emplace_back(new char[64 << 20]);
        hog.back()[0] = 1;
      }
    }
  }
}

}  // namespace

int worker_main() {
  keep_freed_memory();
  std::string line;
  if (!std::getline(std::cin, line)) return 0;
  const TrialContext ctx = context_from_json(nlohmann::json::parse(line));
  while (std::getline(std::cin, line)) {
    if (line.empty()) continue;
    nlohmann::json out;
    try {
      const TrialRecord trial = record_from_json(nlohmann::json::parse(line), "runner input", 0);
      try {
        inject_fault(trial.key);
      } catch (const std::bad_alloc&) {
        TrialRecord rec = trial;
        rec.status = "out_of_memory";
        rec.message = "an allocation failed (injected fault)";
        rec.correct = false;
        std::cout << nlohmann::json(rec).dump() << "\n" << std::flush;
        continue;
      }
      out = run_trial(trial, ctx);
    } catch (const std::exception& e) {
      out = {{"status", "error"}, {"message", e.what()}};  // unreadable input: the runner records the error
    }
    std::cout << out.dump() << "\n" << std::flush;
  }
  return 0;
}

}  // namespace pb
