// parapm up [--workers N] [--data DIR]: the whole service on this machine in the foreground,
// a coordinator and N workers on loopback, as child processes (the same daemons one starts on
// many machines). Ctrl-C (or SIGTERM) stops them all cleanly; killed, it leaves none behind
// (each child gets SIGTERM when it ends). A worker that exits is started
// again, after a pause that doubles with each exit in a row (0.5 s up to 30 s; a worker that
// lived a minute starts the count again); the coordinator exiting stops the rest, exit status 1.
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <thread>

#include <spdlog/spdlog.h>

#include "cli_common.h"
#include "commands.h"
#include "service_client.h"
#include "util/error.h"

namespace parapm::cli {
namespace {

struct UpArgs {
  unsigned workers = 2;
  unsigned worker_threads = 0;
  std::string data = "parapm-data";
  std::string listen = kDefaultServer;
  uint32_t parallelism = 4;
  std::string token_file;
  std::string log_level = "info";
  std::string http = kDefaultViewer;  // the viewer's address; "" : no viewer
};

// The port a daemon wrote to `file` once listening; 0 while it has not.
int port_in(const std::filesystem::path& file) {
  std::ifstream in(file);
  int port = 0;
  return in >> port ? port : 0;
}

std::filesystem::path sibling_program(const std::string& name) {
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe");
  const std::filesystem::path program = self.parent_path() / name;
  if (!std::filesystem::exists(program))
    throw Error(ErrorCode::kNotFound, program.string() +
                                          " not found (build the service: it is "
                                          "built beside parapm)");
  return program;
}

// The child process of `program`, started from the main thread. It stops (SIGTERM) when this
// process ends, however it ends (a SIGKILL or a crash too), so that no coordinator or worker
// outlives `parapm up` holding its ports.
pid_t spawn(const std::filesystem::path& program, const std::vector<std::string>& args) {
  std::vector<char*> argv;
  std::string name = program.string();
  argv.push_back(name.data());
  std::vector<std::string> copy = args;
  for (std::string& a : copy) argv.push_back(a.data());
  argv.push_back(nullptr);
  // Everything is prepared before fork(): between fork() and exec() only async-signal-safe
  // calls. The children must see SIGINT / SIGTERM, which this process blocks for sigwait.
  sigset_t none;
  sigemptyset(&none);
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid == 0) {
    sigprocmask(SIG_SETMASK, &none, nullptr);
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (getppid() != parent) _exit(126);  // the parent ended before the line above
    execv(name.c_str(), argv.data());
    _exit(127);
  }
  if (pid < 0) throw Error(ErrorCode::kIo, "cannot start " + name + ": " + std::strerror(errno));
  return pid;
}

// Stops the children: SIGTERM, then SIGKILL for any still there after `grace`.
void stop_all(std::vector<pid_t>& children, std::chrono::seconds grace) {
  for (pid_t pid : children) kill(pid, SIGTERM);
  const auto deadline = std::chrono::steady_clock::now() + grace;
  while (!children.empty()) {
    for (auto it = children.begin(); it != children.end();) {
      int status = 0;
      if (waitpid(*it, &status, WNOHANG) == *it)
        it = children.erase(it);
      else
        ++it;
    }
    if (children.empty()) break;
    if (std::chrono::steady_clock::now() > deadline) {
      for (pid_t pid : children) {
        spdlog::warn("process {} did not stop in time: killing it", pid);
        kill(pid, SIGKILL);
        waitpid(pid, nullptr, 0);
      }
      children.clear();
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
}

// A worker `parapm up` keeps running: started again when it exits, with a growing pause.
struct WorkerProcess {
  std::string name;
  std::vector<std::string> args;
  pid_t pid = -1;  // -1 while waiting to be started again
  std::chrono::steady_clock::time_point started, restart_at;
  unsigned exits_in_a_row = 0;
};

constexpr auto kFirstRestartPause = std::chrono::milliseconds(500);
constexpr auto kLongestRestartPause = std::chrono::seconds(30);
constexpr auto kHealthyLifetime = std::chrono::seconds(60);  // resets the pause

void start_worker(WorkerProcess& worker) {
  worker.pid = spawn(sibling_program("parapm-worker"), worker.args);
  worker.started = std::chrono::steady_clock::now();
  std::fprintf(stderr, "parapm up: %s is process %d\n", worker.name.c_str(), int(worker.pid));
}

std::string exit_text(int status) {
  return WIFEXITED(status) ? "status " + std::to_string(WEXITSTATUS(status))
                           : "signal " + std::to_string(WTERMSIG(status));
}

// Waits for Ctrl-C / SIGTERM or the coordinator's exit, restarting workers that exit; returns
// the exit status of `parapm up` (0: stopped by a signal; 1: the coordinator exited).
int supervise(pid_t coordinator, std::vector<WorkerProcess>& workers, const sigset_t& signals) {
  using Clock = std::chrono::steady_clock;
  while (true) {
    // Sleep until a signal, or the next restart that is due.
    auto wait = std::chrono::milliseconds(1000);
    for (const WorkerProcess& w : workers)
      if (w.pid < 0)
        wait = std::min(wait, std::max(std::chrono::milliseconds(0),
                                       std::chrono::duration_cast<std::chrono::milliseconds>(
                                           w.restart_at - Clock::now())));
    timespec timeout{time_t(wait.count() / 1000), long(wait.count() % 1000) * 1000000};
    const int signal = sigtimedwait(&signals, nullptr, &timeout);
    if (signal == SIGINT || signal == SIGTERM) {
      std::fprintf(stderr, "parapm up: stopping\n");
      return 0;
    }
    int status = 0;
    for (pid_t pid; (pid = waitpid(-1, &status, WNOHANG)) > 0;) {
      if (pid == coordinator) {
        std::fprintf(stderr, "parapm up: the coordinator exited (%s); stopping the workers\n",
                     exit_text(status).c_str());
        return 1;
      }
      for (WorkerProcess& w : workers) {
        if (w.pid != pid) continue;
        w.pid = -1;
        if (Clock::now() - w.started > kHealthyLifetime) w.exits_in_a_row = 0;
        const auto pause = std::min<std::chrono::milliseconds>(
            kLongestRestartPause, kFirstRestartPause * (1u << std::min(w.exits_in_a_row, 6u)));
        ++w.exits_in_a_row;
        w.restart_at = Clock::now() + pause;
        std::fprintf(stderr,
                     "parapm up: %s (process %d) exited (%s); starting it again in %.1f s\n",
                     w.name.c_str(), int(pid), exit_text(status).c_str(),
                     std::chrono::duration<double>(pause).count());
      }
    }
    for (WorkerProcess& w : workers)
      if (w.pid < 0 && Clock::now() >= w.restart_at) start_worker(w);
  }
}

int run_up(const UpArgs& args) {
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGCHLD);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  std::filesystem::create_directories(args.data);
  const std::filesystem::path port_file = std::filesystem::path(args.data) / "coordinator.port";
  const std::filesystem::path http_port_file = std::filesystem::path(args.data) / "viewer.port";
  std::filesystem::remove(port_file);
  std::filesystem::remove(http_port_file);
  const unsigned hardware = std::max(1u, std::thread::hardware_concurrency());
  const unsigned threads = args.worker_threads
                               ? args.worker_threads
                               : std::max(1u, hardware / std::max(1u, args.workers));
  std::vector<std::string> coordinator_args = {
      "--listen",    args.listen,        "--data",        args.data,
      "--port-file", port_file.string(), "--parallelism", std::to_string(args.parallelism),
      "--log-level", args.log_level};
  if (args.workers == 0) {
    // No worker: the coordinator runs the subsets itself.
    coordinator_args.push_back("--local-threads");
    coordinator_args.push_back(std::to_string(hardware));
  }
  if (!args.token_file.empty()) {
    coordinator_args.push_back("--token-file");
    coordinator_args.push_back(args.token_file);
  }
  if (!args.http.empty())
    coordinator_args.insert(coordinator_args.end(),
                            {"--http", args.http, "--http-port-file", http_port_file.string()});
  std::vector<pid_t> children;
  children.push_back(spawn(sibling_program("parapm-coordinator"), coordinator_args));

  // Serving once the port files appear; a coordinator that exits first failed to start.
  int port = 0, http_port = 0;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (port == 0 || (!args.http.empty() && http_port == 0)) {
    int status = 0;
    if (waitpid(children[0], &status, WNOHANG) == children[0]) {
      std::fprintf(stderr, "parapm up: the coordinator exited at start (status %d); see above\n",
                   WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status));
      return 2;
    }
    port = port_in(port_file);
    http_port = port_in(http_port_file);
    if (port != 0 && (args.http.empty() || http_port != 0)) break;
    if (std::chrono::steady_clock::now() > deadline) {
      stop_all(children, std::chrono::seconds(2));
      throw Error(ErrorCode::kIo, "the coordinator did not start listening within 30 s");
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  const std::string host = args.listen.substr(0, args.listen.rfind(':'));
  const std::string address =
      (host == "0.0.0.0" || host.empty() ? std::string("127.0.0.1") : host) + ":" +
      std::to_string(port);
  if (!args.http.empty()) {
    const std::string http_host = args.http.substr(0, args.http.rfind(':'));
    std::fprintf(stderr, "viewer: http://%s:%d/\n",
                 http_host == "0.0.0.0" || http_host.empty() ? "127.0.0.1" : http_host.c_str(),
                 http_port);
  }
  std::vector<WorkerProcess> workers(args.workers);
  for (unsigned i = 0; i < args.workers; ++i) {
    WorkerProcess& worker = workers[i];
    worker.name = "worker-" + std::to_string(i + 1);
    worker.args = {"--coordinator",         address,  "--listen",  "127.0.0.1:0", "--threads",
                   std::to_string(threads), "--name", worker.name, "--log-level", args.log_level};
    if (!args.token_file.empty()) {
      worker.args.push_back("--token-file");
      worker.args.push_back(args.token_file);
    }
    start_worker(worker);
  }
  std::fprintf(stderr,
               "ParaPM is up: coordinator at %s (data in %s), %u workers of %u threads. "
               "Ctrl-C stops them all.\n",
               address.c_str(), args.data.c_str(), args.workers, threads);

  const int exit_code = supervise(children[0], workers, signals);
  if (exit_code != 0) children.clear();  // the coordinator exited, and was reaped
  for (const WorkerProcess& worker : workers)
    if (worker.pid > 0) children.push_back(worker.pid);
  stop_all(children, std::chrono::seconds(10));
  return exit_code;
}

}  // namespace

void add_up_command(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<UpArgs>();
  CLI::App* up = app.add_subcommand(
      "up",
      "run the service on this machine in the foreground: a coordinator and N workers on "
      "loopback (Ctrl-C stops them all); then 'parapm submit' sends it jobs");
  up->add_option("--workers", args->workers,
                 "worker processes (0: the coordinator runs subsets itself)")
      ->check(CLI::Range(0, 256))
      ->capture_default_str();
  up->add_option("--worker-threads", args->worker_threads,
                 "subsets each worker runs at once (0: the cores shared among the workers)")
      ->capture_default_str();
  up->add_option("--data", args->data, "folder for the coordinator's database and blobs")
      ->capture_default_str();
  up->add_option("--listen", args->listen, "the coordinator's address")->capture_default_str();
  up->add_option("--parallelism", args->parallelism, "subsets p of a job that does not say")
      ->check(CLI::Range(1, 256))
      ->capture_default_str();
  up->add_option("--token-file", args->token_file,
                 "bearer token file for the coordinator and workers (else PARAPM_TOKEN)");
  up->add_option("--http", args->http,
                 "the viewer's address, host:port (port 0: any free; \"\": no viewer); its URL "
                 "is printed once serving")
      ->capture_default_str();
  up->add_option("--log-level", args->log_level, "the daemons' log level")->capture_default_str();
  up->callback([args, &exit_code] { exit_code = run_up(*args); });
}

}  // namespace parapm::cli
