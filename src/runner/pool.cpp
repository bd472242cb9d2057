#include "runner/pool.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include "core/timer.h"

namespace pb {

#if defined(__SANITIZE_ADDRESS__)
const bool kMemoryLimitApplies = false;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
const bool kMemoryLimitApplies = false;
#else
const bool kMemoryLimitApplies = true;
#endif
#else
const bool kMemoryLimitApplies = true;
#endif

namespace {

struct Worker {
  pid_t pid = -1;
  int in_fd = -1;   // we write trials here
  int out_fd = -1;  // we read records here
  std::string buf;
  long trial = -1;  // index into trials, -1 idle
  Timer started;
};

Worker spawn_worker(const PoolOptions& opt) {
  int to_child[2], from_child[2];
  if (pipe(to_child) != 0 || pipe(from_child) != 0) throw std::runtime_error("pipe failed");
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("fork failed");
  if (pid == 0) {
    // A worker dies with its runner (killed or not): no orphan goes on
    // computing a trial whose record nobody will write.
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != parent) _exit(127);
    if (opt.memory_limit_mb > 0 && kMemoryLimitApplies) {
      const rlim_t bytes = static_cast<rlim_t>(opt.memory_limit_mb) * 1024 * 1024;
      const rlimit lim{bytes, bytes};
      setrlimit(RLIMIT_AS, &lim);
    }
    dup2(to_child[0], 0);
    dup2(from_child[1], 1);
    const int fd = ::open(opt.log_path.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
    if (fd >= 0) dup2(fd, 2);
    close(to_child[1]);
    close(from_child[0]);
    setenv("OMP_NUM_THREADS", std::to_string(opt.omp_threads).c_str(), 1);
    execl(opt.binary.c_str(), opt.binary.c_str(), "worker", static_cast<char*>(nullptr));
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
  const std::string line = opt.context + "\n";
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

// The pool's state: the workers, what is pending, what is running.
class Pool {
 public:
  Pool(const PoolOptions& opt, const std::vector<TrialRecord>& inputs, std::deque<long> pending,
       const std::function<void(long, const TrialRecord&)>& on_record)
      : opt_(opt), inputs_(inputs), pending_(std::move(pending)), on_record_(on_record) {}

  void run() {
    signal(SIGPIPE, SIG_IGN);
    const int n = std::max(1, std::min<int>(opt_.jobs, static_cast<int>(pending_.size())));
    for (int i = 0; i < n; ++i) workers_.push_back(spawn());
    for (auto& w : workers_) dispatch(w);
    while (active_ > 0) {
      std::vector<pollfd> fds;
      for (auto& w : workers_) fds.push_back({w.out_fd, POLLIN, 0});
      poll(fds.data(), fds.size(), 200);
      for (size_t i = 0; i < workers_.size(); ++i) service(workers_[i], fds[i].revents);
    }
    for (auto& w : workers_)
      if (w.pid >= 0) stop_worker(w, false);
  }

 private:
  Worker spawn() { return spawn_worker(opt_); }

  // The input record with a failure outcome (the worker's own record is
  // lost: no times, no wall_s).
  TrialRecord failed(long ti, const std::string& status, const std::string& msg) const {
    TrialRecord rec = inputs_[static_cast<size_t>(ti)];
    rec.status = status;
    rec.message = msg;
    rec.correct = false;
    return rec;
  }

  void finish(Worker& w, const TrialRecord& rec) {
    const long ti = w.trial;
    w.trial = -1;
    --active_;
    on_record_(ti, rec);
  }

  void dispatch(Worker& w) {
    if (pending_.empty() || w.pid < 0) return;
    const long ti = pending_.front();
    pending_.pop_front();
    const std::string line = nlohmann::json(inputs_[static_cast<size_t>(ti)]).dump() + "\n";
    w.trial = ti;
    w.started.reset();
    if (write(w.in_fd, line.data(), line.size()) != static_cast<ssize_t>(line.size())) {
      // The worker died before taking the trial: requeue and respawn.
      pending_.push_front(ti);
      w.trial = -1;
      stop_worker(w, true);
      w = spawn();
      return;
    }
    ++active_;
  }

  // Reads what the worker wrote; handles its records, its death, its time-out.
  void service(Worker& w, short revents) {
    if (w.pid < 0) return;
    bool dead = false;
    if (revents & (POLLIN | POLLHUP | POLLERR)) {
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
      finish(w, parse(w, line));
      dispatch(w);
    }
    if (dead) return on_death(w);
    if (w.trial >= 0 && w.started.seconds() > opt_.timeout_s) {
      const TrialRecord rec =
          failed(w.trial, "timeout", "exceeded the time limit of " + std::to_string(opt_.timeout_s) + " s");
      stop_worker(w, true);
      finish(w, rec);
      respawn(w);
    }
  }

  // The worker's record, checked strictly; an unreadable one is an error record.
  TrialRecord parse(const Worker& w, const std::string& line) const {
    try {
      TrialRecord rec = record_from_json(nlohmann::json::parse(line), "worker output", 0);
      rec.key = inputs_[static_cast<size_t>(w.trial)].key;
      return rec;
    } catch (const std::exception& e) {
      return failed(w.trial, "error", std::string("worker wrote an unreadable record: ") + e.what());
    }
  }

  void on_death(Worker& w) {
    int status = 0;
    close(w.in_fd);
    close(w.out_fd);
    waitpid(w.pid, &status, 0);
    const long ti = w.trial;
    w.pid = -1;
    if (ti >= 0) {
      std::string why = WIFSIGNALED(status) ? "worker crashed (signal " + std::to_string(WTERMSIG(status)) + ")"
                                            : "worker exited (code " + std::to_string(WEXITSTATUS(status)) + ")";
      if (opt_.memory_limit_mb > 0 && kMemoryLimitApplies && WIFSIGNALED(status))
        why += " under a memory limit of " + std::to_string(opt_.memory_limit_mb) + " MB (an allocation that "
               "failed outside C++ can end a worker this way)";
      finish(w, failed(ti, "error", why + "; see " + opt_.log_path));
    }
    w = Worker{};
    respawn(w);
  }

  void respawn(Worker& w) {
    if (pending_.empty()) return;
    w = spawn();
    dispatch(w);
  }

  const PoolOptions& opt_;
  const std::vector<TrialRecord>& inputs_;
  std::deque<long> pending_;
  const std::function<void(long, const TrialRecord&)>& on_record_;
  std::vector<Worker> workers_;
  size_t active_ = 0;
};

}  // namespace

void run_in_workers(const PoolOptions& opt, const std::vector<TrialRecord>& inputs, std::deque<long> pending,
                    const std::function<void(long, const TrialRecord&)>& on_record) {
  Pool(opt, inputs, std::move(pending), on_record).run();
}

int omp_threads_per_worker(int jobs, int host_cores) {
  const char* env = std::getenv("OMP_NUM_THREADS");
  if (env && *env) {
    char* end = nullptr;
    const long v = std::strtol(env, &end, 10);
    if (end && *end == '\0' && v > 0) return static_cast<int>(v);
  }
  return std::max(1, host_cores / std::max(1, jobs));
}

}  // namespace pb
