// parapm up [--workers N] [--data DIR]: the whole service on this machine in the foreground,
// a coordinator and N workers on loopback, as child processes (the same daemons one starts on
// many machines). Ctrl-C (or SIGTERM) stops them all cleanly; if one dies, the rest are
// stopped and the exit status is 1.
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <thread>

#include <spdlog/spdlog.h>

#include "cli_common.h"
#include "commands.h"
#include "service_client.h"
#include "util/error.h"

extern char** environ;

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
};

std::filesystem::path sibling_program(const std::string& name) {
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe");
  const std::filesystem::path program = self.parent_path() / name;
  if (!std::filesystem::exists(program))
    throw Error(ErrorCode::kNotFound, program.string() +
                                          " not found (build the service: it is "
                                          "built beside parapm)");
  return program;
}

pid_t spawn(const std::filesystem::path& program, const std::vector<std::string>& args) {
  std::vector<char*> argv;
  std::string name = program.string();
  argv.push_back(name.data());
  std::vector<std::string> copy = args;
  for (std::string& a : copy) argv.push_back(a.data());
  argv.push_back(nullptr);
  // The children must see SIGINT / SIGTERM, which this process blocks for sigwait.
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  sigset_t none;
  sigemptyset(&none);
  posix_spawnattr_setsigmask(&attr, &none);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGMASK);
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, name.c_str(), nullptr, &attr, argv.data(), environ);
  posix_spawnattr_destroy(&attr);
  if (rc != 0) throw Error(ErrorCode::kIo, "cannot start " + name + ": " + std::strerror(rc));
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

int run_up(const UpArgs& args) {
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGCHLD);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  std::filesystem::create_directories(args.data);
  const std::filesystem::path port_file = std::filesystem::path(args.data) / "coordinator.port";
  std::filesystem::remove(port_file);
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
  std::vector<pid_t> children;
  children.push_back(spawn(sibling_program("parapm-coordinator"), coordinator_args));

  // Serving once the port file appears; a coordinator that exits first failed to start.
  int port = 0;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (port == 0) {
    int status = 0;
    if (waitpid(children[0], &status, WNOHANG) == children[0]) {
      std::fprintf(stderr, "parapm up: the coordinator exited at start (status %d); see above\n",
                   WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status));
      return 2;
    }
    std::ifstream in(port_file);
    if (in >> port) break;
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
  for (unsigned i = 0; i < args.workers; ++i) {
    std::vector<std::string> worker_args = {"--coordinator", address,
                                            "--listen",      "127.0.0.1:0",
                                            "--threads",     std::to_string(threads),
                                            "--name",        "worker-" + std::to_string(i + 1),
                                            "--log-level",   args.log_level};
    if (!args.token_file.empty()) {
      worker_args.push_back("--token-file");
      worker_args.push_back(args.token_file);
    }
    children.push_back(spawn(sibling_program("parapm-worker"), worker_args));
  }
  std::fprintf(stderr,
               "ParaPM is up: coordinator at %s (data in %s), %u workers of %u threads. "
               "Ctrl-C stops them all.\n",
               address.c_str(), args.data.c_str(), args.workers, threads);

  int exit_code = 0;
  while (true) {
    int signal = 0;
    sigwait(&signals, &signal);
    if (signal != SIGCHLD) {
      std::fprintf(stderr, "parapm up: stopping\n");
      break;
    }
    int status = 0;
    const pid_t pid = waitpid(-1, &status, WNOHANG);
    if (pid <= 0) continue;
    std::erase(children, pid);
    std::fprintf(stderr, "parapm up: process %d exited (status %d); stopping the others\n", pid,
                 WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status));
    exit_code = 1;
    break;
  }
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
  up->add_option("--log-level", args->log_level, "the daemons' log level")->capture_default_str();
  up->callback([args, &exit_code] { exit_code = run_up(*args); });
}

}  // namespace parapm::cli
