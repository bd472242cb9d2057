#include "runner/runner.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "core/error.h"
#include "core/timer.h"
#include "core/yaml.h"
#include "io/png.h"
#include "runner/store.h"
#include "runner/trial.h"

namespace fs = std::filesystem;

namespace pb {

static nlohmann::json yaml_to_json_file(const std::string& path) {
  // The generator configs are YAML; merge overrides at the JSON level and
  // write JSON (a YAML subset) for the generator to read.
  const YamlNode n = YamlNode::load_file(path);
  std::function<nlohmann::json(const YAML::Node&)> conv = [&](const YAML::Node& y) -> nlohmann::json {
    if (y.IsMap()) {
      nlohmann::json j = nlohmann::json::object();
      for (const auto& kv : y) j[kv.first.as<std::string>()] = conv(kv.second);
      return j;
    }
    if (y.IsSequence()) {
      nlohmann::json j = nlohmann::json::array();
      for (const auto& e : y) j.push_back(conv(e));
      return j;
    }
    if (!y.IsDefined() || y.IsNull()) return nullptr;
    const std::string s = y.Scalar();
    if (y.Tag() == "!") return s;
    if (s == "true" || s == "false") return s == "true";
    char* end = nullptr;
    const long long iv = std::strtoll(s.c_str(), &end, 10);
    if (!s.empty() && *end == '\0') return iv;
    const double dv = std::strtod(s.c_str(), &end);
    if (!s.empty() && *end == '\0') return dv;
    return s;
  };
  return conv(n.raw());
}

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

void prepare_scenes(ExperimentConfig& cfg, const RunOptions& opt) {
  for (auto& src : cfg.scenes) {
    if (src.generate.empty()) continue;
    nlohmann::json gen = yaml_to_json_file(src.generate);
    for (auto it = src.generator_overrides.begin(); it != src.generator_overrides.end(); ++it)
      gen[it.key()] = it.value();
    // The copy lives in scenes_dir: make a relative registry path absolute
    // against the original config's folder.
    if (gen.contains("registry") && gen["registry"].is_string() &&
        fs::path(gen["registry"].get<std::string>()).is_relative())
      gen["registry"] = fs::absolute(fs::path(src.generate).parent_path() / gen["registry"].get<std::string>())
                            .lexically_normal()
                            .string();
    const std::string h = hash_hex(gen.dump()).substr(0, 8);
    const fs::path dir = fs::path(opt.scenes_dir) / (src.name + "_" + h);
    src.dataset = dir.string();
    if (fs::exists(dir / "models" / "models_info.json") && fs::exists(dir / "camera.json")) continue;
    fs::create_directories(opt.scenes_dir);
    const fs::path cfg_path = fs::path(opt.scenes_dir) / (src.name + "_" + h + ".config.json");
    atomic_write_text(cfg_path.string(), gen.dump(2) + "\n");
    const std::string log = (fs::path(opt.scenes_dir) / (src.name + "_" + h + ".log")).string();
    if (!opt.quiet) std::cerr << "posebench run: generating scene set '" << src.name << "' into " << dir << "\n";
    const int rc = run_command({opt.binary, "generate", cfg_path.string(), "--out", dir.string()}, log);
    if (rc != 0) {
      std::ifstream in(log);
      std::stringstream ss;
      ss << in.rdbuf();
      throw InputError(src.generate, "scenes." + src.name, "scene generation failed (exit " + std::to_string(rc) +
                                                             "): " + ss.str());
    }
  }
}

static nlohmann::json trial_json(const Trial& t) {
  return {{"key", t.key},           {"scene", t.scene_name},   {"scenario", t.scenario},
          {"dataset", t.dataset},   {"split", t.split},        {"scene_id", t.scene_id},
          {"im_id", t.im_id},       {"descriptor", t.descriptor}, {"refinement", t.refinement},
          {"params", t.params},     {"added_noise_mm", t.added_noise_mm}, {"settings", t.settings},
          {"seed", t.seed}};
}

namespace {

struct Worker {
  pid_t pid = -1;
  int in_fd = -1;   // we write trials here
  int out_fd = -1;  // we read records here
  std::string buf;
  long trial = -1;  // index into trials, -1 idle
  Timer started;
};

Worker spawn_worker(const std::string& binary, const std::string& ctx_line, const std::string& log_path) {
  int to_child[2], from_child[2];
  if (pipe(to_child) != 0 || pipe(from_child) != 0) throw std::runtime_error("pipe failed");
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("fork failed");
  if (pid == 0) {
    dup2(to_child[0], 0);
    dup2(from_child[1], 1);
    const int fd = ::open(log_path.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
    if (fd >= 0) dup2(fd, 2);
    close(to_child[1]);
    close(from_child[0]);
    execl(binary.c_str(), binary.c_str(), "worker", static_cast<char*>(nullptr));
    _exit(127);
  }
  close(to_child[0]);
  close(from_child[1]);
  Worker w;
  w.pid = pid;
  w.in_fd = to_child[1];
  w.out_fd = from_child[0];
  fcntl(w.out_fd, F_SETFD, FD_CLOEXEC);
  fcntl(w.in_fd, F_SETFD, FD_CLOEXEC);
  const std::string line = ctx_line + "\n";
  if (write(w.in_fd, line.data(), line.size()) != static_cast<ssize_t>(line.size()))
    throw std::runtime_error("cannot talk to worker");
  return w;
}

void stop_worker(Worker& w, bool kill_it) {
  if (w.in_fd >= 0) close(w.in_fd);
  if (w.out_fd >= 0) close(w.out_fd);
  if (kill_it) kill(w.pid, SIGKILL);
  int status = 0;
  waitpid(w.pid, &status, 0);
  w = Worker{};
}

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

}  // namespace

RunSummary run_experiment(ExperimentConfig cfg, const RunOptions& opt) {
  RunSummary sum;
  Timer timer;
  const std::string out = opt.out_dir.empty() ? "results/" + cfg.name : opt.out_dir;
  // Guard the folder before doing anything expensive, but create it only
  // once the scenes and trials are known to be valid.
  ResultStore::check(out, cfg.hash);
  prepare_scenes(cfg, opt);
  const std::vector<Trial> trials = expand_trials(cfg);
  ResultStore store(out, cfg.canonical, cfg.hash);
  sum.total = trials.size();

  std::deque<long> pending;
  for (long i = 0; i < static_cast<long>(trials.size()); ++i)
    if (!store.has(trials[i].key)) pending.push_back(i);
  sum.already_done = trials.size() - pending.size();
  if (!opt.quiet && sum.already_done)
    std::cerr << "posebench run: resuming: " << sum.already_done << " of " << sum.total
              << " trials already recorded\n";
  if (pending.empty()) {
    sum.seconds = timer.seconds();
    return sum;
  }

  nlohmann::json ctx = {{"object", cfg.object},
                        {"cache_dir", opt.cache_dir},
                        {"table_translation_mm", cfg.thresholds.table_translation_mm},
                        {"warehouse_translation_mm", cfg.thresholds.warehouse_translation_mm},
                        {"rotation_1mpq", cfg.thresholds.rotation_1mpq},
                        {"registration_only", cfg.registration_only},
                        {"perturb_deg", cfg.perturb_deg},
                        {"perturb_mm", cfg.perturb_mm}};
  const std::string ctx_line = ctx.dump();
  const std::string log_path = (fs::path(out) / "workers.log").string();
  signal(SIGPIPE, SIG_IGN);

  const int njobs = std::max(1, std::min<int>(opt.jobs, static_cast<int>(pending.size())));
  std::vector<Worker> workers;
  for (int i = 0; i < njobs; ++i) workers.push_back(spawn_worker(opt.binary, ctx_line, log_path));

  const bool tty = isatty(2);
  Timer last_print;
  const size_t to_run = pending.size();
  auto progress = [&](bool final) {
    if (opt.quiet) return;
    const double el = timer.seconds();
    const double frac = to_run ? static_cast<double>(sum.ran) / to_run : 1.0;
    const double eta = sum.ran ? el / sum.ran * (to_run - sum.ran) : NAN;
    char line[256];
    if (tty) {
      const int width = 30, filled = static_cast<int>(frac * width);
      std::string bar(filled, '#');
      bar += std::string(width - filled, '.');
      std::snprintf(line, sizeof line, "\r[%s] %zu/%zu %3.0f%%  elapsed %s  ETA %s  ok %zu none %zu err %zu tmo %zu ",
                    bar.c_str(), sum.ran, to_run, 100 * frac, fmt_duration(el).c_str(),
                    fmt_duration(eta).c_str(), sum.ok, sum.no_hypothesis, sum.errors, sum.timeouts);
      std::cerr << line << (final ? "\n" : "") << std::flush;
    } else if (final || last_print.seconds() > 10) {
      std::snprintf(line, sizeof line, "posebench run: %zu/%zu trials (%.0f%%), elapsed %s, ETA %s\n", sum.ran,
                    to_run, 100 * frac, fmt_duration(el).c_str(), fmt_duration(eta).c_str());
      std::cerr << line;
      last_print.reset();
    }
  };

  auto record = [&](const nlohmann::json& rec) {
    store.append(rec);
    ++sum.ran;
    const std::string st = rec.value("status", "error");
    if (st == "ok") ++sum.ok;
    else if (st == "no_hypothesis") ++sum.no_hypothesis;
    else if (st == "timeout") ++sum.timeouts;
    else ++sum.errors;
    progress(false);
  };
  auto failed_record = [&](long ti, const std::string& status, const std::string& msg) {
    nlohmann::json rec = trial_json(trials[ti]);
    rec["status"] = status;
    rec["message"] = msg;
    rec["correct"] = false;
    return rec;
  };

  size_t active = 0;
  auto dispatch = [&](Worker& w) {
    if (pending.empty() || w.pid < 0) return;
    const long ti = pending.front();
    pending.pop_front();
    const std::string line = trial_json(trials[ti]).dump() + "\n";
    w.trial = ti;
    w.started.reset();
    if (write(w.in_fd, line.data(), line.size()) != static_cast<ssize_t>(line.size())) {
      // The worker died before taking the trial: requeue and respawn.
      pending.push_front(ti);
      w.trial = -1;
      stop_worker(w, true);
      w = spawn_worker(opt.binary, ctx_line, log_path);
      return;
    }
    ++active;
  };
  for (auto& w : workers) dispatch(w);

  while (active > 0) {
    std::vector<pollfd> fds;
    for (auto& w : workers) fds.push_back({w.out_fd, POLLIN, 0});
    poll(fds.data(), fds.size(), 200);
    for (size_t i = 0; i < workers.size(); ++i) {
      Worker& w = workers[i];
      if (w.pid < 0) continue;
      bool dead = false;
      if (fds[i].revents & (POLLIN | POLLHUP | POLLERR)) {
        char chunk[65536];
        const ssize_t n = read(w.out_fd, chunk, sizeof chunk);
        if (n > 0)
          w.buf.append(chunk, static_cast<size_t>(n));
        else
          dead = true;
      }
      size_t nl;
      while ((nl = w.buf.find('\n')) != std::string::npos) {
        const std::string line = w.buf.substr(0, nl);
        w.buf.erase(0, nl + 1);
        if (w.trial < 0) continue;
        nlohmann::json rec;
        try {
          rec = nlohmann::json::parse(line);
        } catch (const nlohmann::json::exception&) {
          rec = failed_record(w.trial, "error", "worker wrote an unreadable record");
        }
        const long ti = w.trial;
        w.trial = -1;
        --active;
        rec["key"] = trials[ti].key;
        record(rec);
        dispatch(w);
      }
      if (dead) {
        const long ti = w.trial;
        int status = 0;
        close(w.in_fd);
        close(w.out_fd);
        waitpid(w.pid, &status, 0);
        w = Worker{};
        if (ti >= 0) {
          --active;
          std::string why = WIFSIGNALED(status) ? "worker crashed (signal " + std::to_string(WTERMSIG(status)) + ")"
                                                : "worker exited (code " + std::to_string(WEXITSTATUS(status)) + ")";
          record(failed_record(ti, "error", why + "; see " + log_path));
        }
        if (!pending.empty()) {
          w = spawn_worker(opt.binary, ctx_line, log_path);
          dispatch(w);
        }
        continue;
      }
      if (w.trial >= 0 && w.started.seconds() > cfg.timeout_s) {
        const long ti = w.trial;
        stop_worker(w, true);
        --active;
        record(failed_record(ti, "timeout", "exceeded the time limit of " + std::to_string(cfg.timeout_s) + " s"));
        if (!pending.empty()) {
          w = spawn_worker(opt.binary, ctx_line, log_path);
          dispatch(w);
        }
      }
    }
  }
  for (auto& w : workers)
    if (w.pid >= 0) stop_worker(w, false);
  progress(true);
  sum.seconds = timer.seconds();
  return sum;
}

int worker_main() {
  std::string line;
  if (!std::getline(std::cin, line)) return 0;
  const nlohmann::json c = nlohmann::json::parse(line);
  TrialContext ctx;
  ctx.object = c.at("object");
  ctx.cache_dir = c.value("cache_dir", "");
  ctx.table_translation_mm = c.value("table_translation_mm", 50.0);
  ctx.warehouse_translation_mm = c.value("warehouse_translation_mm", 100.0);
  ctx.rotation_1mpq = c.value("rotation_1mpq", 0.05);
  ctx.registration_only = c.value("registration_only", false);
  ctx.perturb_deg = c.value("perturb_deg", 10.0);
  ctx.perturb_mm = c.value("perturb_mm", 20.0);
  while (std::getline(std::cin, line)) {
    if (line.empty()) continue;
    nlohmann::json rec;
    try {
      rec = run_trial(nlohmann::json::parse(line), ctx);
    } catch (const std::exception& e) {
      rec = {{"status", "error"}, {"message", e.what()}};
    }
    std::cout << rec.dump() << "\n" << std::flush;
  }
  return 0;
}

}  // namespace pb
