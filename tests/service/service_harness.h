// A harness for testing the service as it runs: real parapm-coordinator and parapm-worker
// processes on loopback, each writing its log to a file in the test's folder, and client
// helpers over the real gRPC API (upload, submit, watch, download). Every wait has a timeout
// and fails with the processes' logs; every process started is killed when the harness goes
// (and, through PR_SET_PDEATHSIG, when the test program dies), so a test never hangs and
// leaves nothing behind.
//
// Client helpers throw ServiceError on a failed call (GoogleTest reports the exception as the
// test's failure); the try_* variants return the status for tests that expect an error.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <grpcpp/grpcpp.h>

#include "parapm.grpc.pb.h"

namespace parapm::service_test {

namespace fs = std::filesystem;
using std::chrono::milliseconds;
using std::chrono::seconds;

// A failed call or a wait that timed out.
class ServiceError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

std::string status_text(const grpc::Status& status);  // "NOT_FOUND: no job 'x'"
std::string read_text(const fs::path& path);          // "" when absent
std::string read_binary(const fs::path& path);        // throws when absent
void write_binary(const fs::path& path, const std::string& bytes);

// One child process; stdout and stderr go to `log`. Killed (SIGKILL) and reaped by the
// destructor when still running.
class ChildProcess {
 public:
  ChildProcess(std::string name, const std::vector<std::string>& argv, fs::path log);
  ~ChildProcess();
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  const std::string& name() const { return name_; }
  pid_t pid() const { return pid_; }
  const fs::path& log_path() const { return log_; }
  std::string log() const { return read_text(log_); }
  bool running();  // false once it exited (reaped here)
  void signal(int sig);
  // Waits for the exit; the raw wait status, or nullopt when still running at the timeout.
  std::optional<int> wait(milliseconds timeout);
  // SIGKILL, then reap.
  void kill_now();
  // CPU time used so far (user + system), from /proc; 0 once it exited.
  double cpu_seconds() const;

 private:
  std::string name_;
  fs::path log_;
  pid_t pid_ = -1;
  std::optional<int> exit_status_;
};

struct CliResult {
  int exit_code = -1;  // -1: killed by a signal or timed out
  std::string output;  // stdout and stderr
};
// Runs build/bin/parapm with `args`; its output goes through a log file in `dir`.
CliResult run_parapm(const std::vector<std::string>& args, const fs::path& dir,
                     milliseconds timeout = seconds(120));

// The `parapm simplify` arguments meaning what `options` means in a job (parallelism,
// rounds, metric, target, seed, samples, crease angle, attribute weight, handover, extra
// rounds).
std::vector<std::string> simplify_args(const parapm::v1::JobOptions& options);
// The .pm `parapm simplify IN --parallel P ...` writes for these options; built once per
// (mesh, options) and kept for the program's life.
std::string reference_pm(const fs::path& mesh, const parapm::v1::JobOptions& options,
                         const fs::path& dir);
// Runs `parapm check PM --against MESH`; "" when lossless, else the exit code and output.
std::string lossless_failure(const std::string& pm_bytes, const fs::path& mesh,
                             const fs::path& dir);

struct WatchResult {
  grpc::Status status;
  std::vector<parapm::v1::JobEvent> events;
  bool finished() const;  // the last event is finished / failed / cancelled
};

bool is_terminal(const parapm::v1::JobEvent& event);
std::string describe(const parapm::v1::JobEvent& event);  // one line, for messages

// A coordinator and its workers, all under `dir` (logs, data, port and token files).
class Service {
 public:
  explicit Service(fs::path dir);
  ~Service();  // kills every process still running

  const fs::path& dir() const { return dir_; }
  // Set before starting anything: the coordinator and the workers get it as --token-file,
  // the client helpers send it.
  void set_token(const std::string& token);
  const std::string& token() const { return token_; }

  // Starts the coordinator on 127.0.0.1 (port 0 the first time, the same port afterwards)
  // with --data dir/data, and waits for its port file. `extra`: more flags.
  void start_coordinator(const std::vector<std::string>& extra = {});
  // Restarts it with the flags of the last start (same port, same data).
  void restart_coordinator();
  ChildProcess& coordinator() { return *coordinator_; }
  bool coordinator_running() const { return coordinator_ != nullptr; }
  // SIGKILL, reaped; the next start_coordinator / restart_coordinator uses the same port.
  void kill_coordinator();
  int port() const { return port_; }
  std::string address() const { return "127.0.0.1:" + std::to_string(port_); }

  // Starts a worker named `name` with --threads `threads`. `extra`: more flags.
  ChildProcess& start_worker(const std::string& name, unsigned threads = 1,
                             const std::vector<std::string>& extra = {});
  ChildProcess* worker(const std::string& name);  // nullptr when unknown
  std::vector<ChildProcess*> workers();
  // Waits until the running coordinator's log shows `count` worker registrations.
  void wait_for_workers(size_t count, milliseconds timeout = seconds(20));
  size_t registrations() const;  // in the running coordinator's log

  // Every process's log (the last `max_lines` lines of each), for failure messages.
  std::string logs(size_t max_lines = 60) const;
  void kill_all();

  // ---- client helpers (the running coordinator's MeshService) ----
  parapm::v1::MeshService::Stub& stub();
  // Sends `bytes` as `file_name` in chunks of `chunk_bytes`; `token`: nullopt sends the
  // service's token, "" none.
  grpc::Status try_upload(const std::string& file_name, const std::string& bytes,
                          parapm::v1::UploadReply* reply,
                          const std::optional<std::string>& token = std::nullopt,
                          size_t chunk_bytes = 256 << 10);
  parapm::v1::UploadReply upload_file(const fs::path& file);
  grpc::Status try_submit(const std::string& mesh_id, const parapm::v1::JobOptions& options,
                          parapm::v1::Job* job);
  parapm::v1::Job submit(const std::string& mesh_id, const parapm::v1::JobOptions& options);
  grpc::Status try_get_job(const std::string& job_id, parapm::v1::Job* job);
  parapm::v1::Job get_job(const std::string& job_id);
  parapm::v1::Job cancel_job(const std::string& job_id);
  // Watches from after `after_seq` until the job's last event, the stream's end, or the
  // timeout (then status is DEADLINE_EXCEEDED). `on_event` sees each event as it arrives.
  WatchResult watch(const std::string& job_id, milliseconds timeout,
                    const std::function<void(const parapm::v1::JobEvent&)>& on_event = {},
                    uint64_t after_seq = 0);
  // Watches until the job ends; throws when it does not end in time. Returns the job.
  parapm::v1::Job wait_for_job(const std::string& job_id, milliseconds timeout,
                               WatchResult* watched = nullptr);
  grpc::Status try_download(const std::string& job_id, std::string* bytes);
  std::string download(const std::string& job_id);

 private:
  fs::path dir_;
  std::string token_;
  fs::path token_file_;
  std::vector<std::string> coordinator_flags_;
  int port_ = 0;
  int coordinator_starts_ = 0;
  std::unique_ptr<ChildProcess> coordinator_;
  std::vector<std::unique_ptr<ChildProcess>> workers_;
  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<parapm::v1::MeshService::Stub> stub_;
};

}  // namespace parapm::service_test
