#include "service_harness.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <map>
#include <mutex>
#include <sstream>
#include <thread>

#include "rpc_security.h"
#include "rpc_status.h"

namespace parapm::service_test {
namespace {

using Clock = std::chrono::steady_clock;

std::string binary(const std::string& name) { return std::string(PARAPM_BINARY_DIR) + "/" + name; }

std::string tail_lines(const std::string& text, size_t max_lines) {
  size_t at = text.size();
  for (size_t lines = 0; at > 0 && lines <= max_lines;) {
    at = text.rfind('\n', at - 1);
    if (at == std::string::npos) return text;
    ++lines;
    if (lines > max_lines) return "...\n" + text.substr(at + 1);
  }
  return text;
}

size_t count_occurrences(const std::string& text, const std::string& needle) {
  size_t count = 0;
  for (size_t at = text.find(needle); at != std::string::npos; at = text.find(needle, at + 1))
    ++count;
  return count;
}

void check_ok(const grpc::Status& status, const std::string& what) {
  if (!status.ok()) throw ServiceError(what + ": " + status_text(status));
}

std::chrono::system_clock::time_point deadline_in(milliseconds timeout) {
  return std::chrono::system_clock::now() + timeout;
}

}  // namespace

std::string status_text(const grpc::Status& status) {
  return std::string(rpc::status_code_name(status.error_code())) + ": " + status.error_message();
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

std::string read_binary(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ServiceError("cannot read " + path.string());
  return std::string(std::istreambuf_iterator<char>(in), {});
}

void write_binary(const fs::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), std::streamsize(bytes.size()));
  if (!out) throw ServiceError("cannot write " + path.string());
}

// ---- ChildProcess

ChildProcess::ChildProcess(std::string name, const std::vector<std::string>& argv, fs::path log)
    : name_(std::move(name)), log_(std::move(log)) {
  // Everything the child needs is prepared before fork(): between fork() and exec() only
  // async-signal-safe calls (the test program has gRPC threads).
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  const int log_fd = ::open(log_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (log_fd < 0) throw ServiceError("cannot create " + log_.string());
  const int null_fd = ::open("/dev/null", O_RDONLY | O_CLOEXEC);
  const pid_t parent = ::getpid();
  pid_ = ::fork();
  if (pid_ == 0) {
    // Dies with the test program, whatever kills it.
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) ::_exit(126);
    ::dup2(null_fd, 0);
    ::dup2(log_fd, 1);
    ::dup2(log_fd, 2);
    ::execv(args[0], args.data());
    ::_exit(127);
  }
  ::close(log_fd);
  if (null_fd >= 0) ::close(null_fd);
  if (pid_ < 0) throw ServiceError("fork failed for " + name_);
}

ChildProcess::~ChildProcess() {
  if (pid_ > 0 && !exit_status_) kill_now();
}

bool ChildProcess::running() {
  if (exit_status_) return false;
  int status = 0;
  if (::waitpid(pid_, &status, WNOHANG) == pid_) {
    exit_status_ = status;
    return false;
  }
  return true;
}

void ChildProcess::signal(int sig) {
  if (running()) ::kill(pid_, sig);
}

std::optional<int> ChildProcess::wait(milliseconds timeout) {
  const auto end = Clock::now() + timeout;
  while (running()) {
    if (Clock::now() >= end) return std::nullopt;
    std::this_thread::sleep_for(milliseconds(5));
  }
  return exit_status_;
}

void ChildProcess::kill_now() {
  if (exit_status_) return;
  ::kill(pid_, SIGKILL);
  int status = 0;
  while (::waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
  }
  exit_status_ = status;
}

double ChildProcess::cpu_seconds() const {
  if (exit_status_) return 0;
  const std::string stat = read_text("/proc/" + std::to_string(pid_) + "/stat");
  // Fields after the command name (which may hold spaces, hence the last ')'): state is
  // field 3, utime and stime fields 14 and 15.
  const size_t close = stat.rfind(')');
  if (close == std::string::npos) return 0;
  std::istringstream fields(stat.substr(close + 2));
  std::string field;
  unsigned long long utime = 0, stime = 0;
  for (int i = 3; i <= 15 && fields >> field; ++i) {
    if (i == 14) utime = std::stoull(field);
    if (i == 15) stime = std::stoull(field);
  }
  return double(utime + stime) / double(::sysconf(_SC_CLK_TCK));
}

// ---- the CLI

CliResult run_parapm(const std::vector<std::string>& args, const fs::path& dir,
                     milliseconds timeout) {
  static std::atomic<int> counter{0};
  std::vector<std::string> argv = {binary("parapm")};
  argv.insert(argv.end(), args.begin(), args.end());
  const fs::path log = dir / ("parapm-cli-" + std::to_string(counter++) + ".log");
  ChildProcess child("parapm " + (args.empty() ? "" : args[0]), argv, log);
  CliResult result;
  const std::optional<int> status = child.wait(timeout);
  if (!status) {
    child.kill_now();
    result.output = "timed out after " + std::to_string(timeout.count()) + " ms\n";
  } else if (WIFEXITED(*status)) {
    result.exit_code = WEXITSTATUS(*status);
  }
  result.output += child.log();
  return result;
}

std::vector<std::string> simplify_args(const parapm::v1::JobOptions& o) {
  std::vector<std::string> args;
  args.insert(args.end(),
              {"--parallel", std::to_string(o.has_parallelism() ? o.parallelism() : 4)});
  if (o.has_rounds()) args.insert(args.end(), {"--rounds", std::to_string(o.rounds())});
  args.insert(args.end(),
              {"--metric", o.metric() == parapm::v1::METRIC_ENERGY ? "energy" : "quadric"});
  if (o.has_target_faces()) args.insert(args.end(), {"--faces", std::to_string(o.target_faces())});
  auto number = [&](const char* flag, double value) {
    std::ostringstream text;
    text.precision(17);
    text << value;
    args.insert(args.end(), {flag, text.str()});
  };
  auto count = [&](const char* flag, uint64_t value) {
    args.insert(args.end(), {flag, std::to_string(value)});
  };
  if (o.quadric_placement() == parapm::v1::QUADRIC_PLACEMENT_CONSTRAINED)
    args.insert(args.end(), {"--quadric-placement", "constrained"});
  if (o.quadric_placement() == parapm::v1::QUADRIC_PLACEMENT_FREE)
    args.insert(args.end(), {"--quadric-placement", "free"});
  if (o.has_target_ratio()) number("--ratio", o.target_ratio());
  if (o.has_seed()) count("--seed", o.seed());
  if (o.has_samples_per_face()) number("--samples-per-face", o.samples_per_face());
  if (o.has_crease_angle_degrees()) number("--crease-angle", o.crease_angle_degrees());
  if (o.has_attribute_weight()) number("--attribute-weight", o.attribute_weight());
  if (o.has_handover_ratio()) number("--handover-ratio", o.handover_ratio());
  if (o.has_border_excess()) number("--border-excess", o.border_excess());
  if (o.has_extra_round_faces()) count("--extra-round-faces", o.extra_round_faces());
  if (o.has_min_subset_faces()) count("--min-subset-faces", o.min_subset_faces());
  const parapm::v1::EnergyTuning& e = o.energy();
  if (e.has_star_planes_weight()) number("--star-planes-weight", e.star_planes_weight());
  if (e.has_volume_weight()) number("--volume-weight", e.volume_weight());
  if (e.has_spring_scale()) number("--spring-scale", e.spring_scale());
  if (e.has_crease_min_length()) number("--crease-min-length", e.crease_min_length());
  if (e.has_min_crease_edges()) count("--crease-min-edges", e.min_crease_edges());
  if (o.keep_order()) args.push_back("--keep-order");
  if (o.free_copies()) args.push_back("--free-copies");
  if (o.keep_components()) args.push_back("--keep-components");
  return args;
}

std::string reference_pm(const fs::path& mesh, const parapm::v1::JobOptions& options,
                         const fs::path& dir) {
  static std::mutex mutex;
  static std::map<std::string, std::string> cache;
  const std::string key = mesh.string() + '\0' + options.SerializeAsString();
  {
    std::lock_guard lock(mutex);
    if (const auto it = cache.find(key); it != cache.end()) return it->second;
  }
  static std::atomic<int> counter{0};
  const fs::path out = dir / ("reference-" + std::to_string(counter++) + ".pm");
  std::vector<std::string> args = {"simplify", mesh.string(), "-o", out.string()};
  const std::vector<std::string> more = simplify_args(options);
  args.insert(args.end(), more.begin(), more.end());
  const CliResult run = run_parapm(args, dir);
  if (run.exit_code != 0) throw ServiceError("parapm simplify failed:\n" + run.output);
  std::string bytes = read_binary(out);
  std::lock_guard lock(mutex);
  cache[key] = bytes;
  return bytes;
}

std::string lossless_failure(const std::string& pm_bytes, const fs::path& mesh,
                             const fs::path& dir) {
  static std::atomic<int> counter{0};
  const fs::path pm = dir / ("checked-" + std::to_string(counter++) + ".pm");
  write_binary(pm, pm_bytes);
  const CliResult run = run_parapm({"check", pm.string(), "--against", mesh.string()}, dir);
  if (run.exit_code == 0) return "";
  return "parapm check exited " + std::to_string(run.exit_code) + ":\n" + run.output;
}

// ---- events

bool is_terminal(const parapm::v1::JobEvent& e) {
  return e.has_finished() || e.has_failed() || e.has_cancelled();
}

bool WatchResult::finished() const { return !events.empty() && is_terminal(events.back()); }

std::string describe(const parapm::v1::JobEvent& e) {
  std::ostringstream s;
  s << "#" << e.seq() << " ";
  switch (e.event_case()) {
    case parapm::v1::JobEvent::kQueued:
      s << "queued";
      break;
    case parapm::v1::JobEvent::kStarted:
      s << "started attempt " << e.started().attempt();
      break;
    case parapm::v1::JobEvent::kPartitioned:
      s << "partitioned round " << e.partitioned().round();
      break;
    case parapm::v1::JobEvent::kSubsetStarted:
      s << "subset " << e.subset_started().subset() << " of round " << e.subset_started().round()
        << " started on " << e.subset_started().worker() << " (attempt "
        << e.subset_started().attempt() << ")";
      break;
    case parapm::v1::JobEvent::kSubsetDone:
      s << "subset " << e.subset_done().subset() << " of round " << e.subset_done().round()
        << " done on " << e.subset_done().worker();
      break;
    case parapm::v1::JobEvent::kMerged:
      s << "merged round " << e.merged().round();
      break;
    case parapm::v1::JobEvent::kProgress:
      s << "progress " << e.progress().done() << "/" << e.progress().total();
      break;
    case parapm::v1::JobEvent::kFinished:
      s << "finished";
      break;
    case parapm::v1::JobEvent::kFailed:
      s << "failed: " << e.failed().reason();
      break;
    case parapm::v1::JobEvent::kCancelled:
      s << "cancelled";
      break;
    default:
      s << "(no event)";
      break;
  }
  return s.str();
}

// ---- Service

Service::Service(fs::path dir) : dir_(std::move(dir)) { fs::create_directories(dir_); }

Service::~Service() { kill_all(); }

void Service::set_token(const std::string& token) {
  token_ = token;
  token_file_ = dir_ / "token";
  write_binary(token_file_, token + "\n");
}

void Service::start_coordinator(const std::vector<std::string>& extra) {
  if (coordinator_ && coordinator_->running())
    throw ServiceError("start_coordinator: the coordinator is still running");
  coordinator_flags_ = extra;
  const int start = ++coordinator_starts_;
  const fs::path port_file = dir_ / ("port-" + std::to_string(start));
  std::vector<std::string> argv = {binary("parapm-coordinator"),
                                   "--listen",
                                   "127.0.0.1:" + std::to_string(port_),
                                   "--data",
                                   (dir_ / "data").string(),
                                   "--port-file",
                                   port_file.string()};
  if (!token_file_.empty()) argv.insert(argv.end(), {"--token-file", token_file_.string()});
  argv.insert(argv.end(), extra.begin(), extra.end());
  // The previous process object stays alive (exited) until replaced, so its log is kept
  // by name: coordinator-1.log, coordinator-2.log, ...
  coordinator_ =
      std::make_unique<ChildProcess>("coordinator#" + std::to_string(start), argv,
                                     dir_ / ("coordinator-" + std::to_string(start) + ".log"));
  const auto end = Clock::now() + seconds(20);
  while (!fs::exists(port_file)) {
    if (!coordinator_->running())
      throw ServiceError("the coordinator exited before serving:\n" + coordinator_->log());
    if (Clock::now() > end)
      throw ServiceError("the coordinator wrote no port file in 20 s:\n" + coordinator_->log());
    std::this_thread::sleep_for(milliseconds(10));
  }
  const int port = std::stoi(read_text(port_file));
  if (port_ != 0 && port != port_)
    throw ServiceError("the coordinator came back on port " + std::to_string(port) +
                       " instead of " + std::to_string(port_));
  port_ = port;
  channel_ = rpc::make_channel(address(), grpc::InsecureChannelCredentials());
  stub_ = parapm::v1::MeshService::NewStub(channel_);
}

void Service::restart_coordinator() { start_coordinator(coordinator_flags_); }

void Service::kill_coordinator() {
  if (coordinator_) coordinator_->kill_now();
}

ChildProcess& Service::start_worker(const std::string& name, unsigned threads,
                                    const std::vector<std::string>& extra) {
  if (port_ == 0) throw ServiceError("start_worker before start_coordinator");
  std::vector<std::string> argv = {
      binary("parapm-worker"), "--coordinator", address(), "--listen", "127.0.0.1:0", "--threads",
      std::to_string(threads), "--name",        name};
  if (!token_file_.empty()) argv.insert(argv.end(), {"--token-file", token_file_.string()});
  argv.insert(argv.end(), extra.begin(), extra.end());
  workers_.push_back(
      std::make_unique<ChildProcess>("worker " + name, argv, dir_ / ("worker-" + name + ".log")));
  return *workers_.back();
}

ChildProcess* Service::worker(const std::string& name) {
  for (auto& w : workers_)
    if (w->name() == "worker " + name) return w.get();
  return nullptr;
}

std::vector<ChildProcess*> Service::workers() {
  std::vector<ChildProcess*> out;
  for (auto& w : workers_) out.push_back(w.get());
  return out;
}

size_t Service::registrations() const {
  // The registry's line: "worker <id> registered: <name> at <address>, ..."
  return coordinator_ ? count_occurrences(coordinator_->log(), " registered: ") : 0;
}

void Service::wait_for_workers(size_t count, milliseconds timeout) {
  const auto end = Clock::now() + timeout;
  while (registrations() < count) {
    if (Clock::now() > end)
      throw ServiceError("only " + std::to_string(registrations()) + " of " +
                         std::to_string(count) + " workers registered in " +
                         std::to_string(timeout.count()) + " ms");
    std::this_thread::sleep_for(milliseconds(20));
  }
}

std::string Service::logs(size_t max_lines) const {
  std::ostringstream out;
  for (int start = 1; start <= coordinator_starts_; ++start) {
    const fs::path log = dir_ / ("coordinator-" + std::to_string(start) + ".log");
    out << "----- " << log.filename().string() << "\n"
        << tail_lines(read_text(log), max_lines) << "\n";
  }
  for (const auto& w : workers_)
    out << "----- " << w->log_path().filename().string() << "\n"
        << tail_lines(w->log(), max_lines) << "\n";
  return out.str();
}

void Service::kill_all() {
  for (auto& w : workers_) w->kill_now();
  if (coordinator_) coordinator_->kill_now();
}

parapm::v1::MeshService::Stub& Service::stub() {
  if (!stub_) throw ServiceError("no coordinator started");
  return *stub_;
}

grpc::Status Service::try_upload(const std::string& file_name, const std::string& bytes,
                                 parapm::v1::UploadReply* reply,
                                 const std::optional<std::string>& token, size_t chunk_bytes) {
  grpc::ClientContext context;
  context.set_deadline(deadline_in(seconds(60)));
  rpc::attach_token(context, token ? *token : token_);
  auto writer = stub().Upload(&context, reply);
  parapm::v1::UploadChunk chunk;
  chunk.set_file_name(file_name);
  for (size_t at = 0; at < bytes.size() || at == 0; at += chunk_bytes) {
    chunk.set_data(bytes.substr(at, chunk_bytes));
    // A failed write: the server ended the call (an error); Finish() says which.
    if (!writer->Write(chunk)) break;
    chunk.clear_file_name();
    if (bytes.empty()) break;
  }
  writer->WritesDone();
  return writer->Finish();
}

parapm::v1::UploadReply Service::upload_file(const fs::path& file) {
  parapm::v1::UploadReply reply;
  check_ok(try_upload(file.filename().string(), read_binary(file), &reply),
           "upload " + file.string());
  return reply;
}

grpc::Status Service::try_submit(const std::string& mesh_id, const parapm::v1::JobOptions& options,
                                 parapm::v1::Job* job) {
  grpc::ClientContext context;
  context.set_deadline(deadline_in(seconds(30)));
  rpc::attach_token(context, token_);
  parapm::v1::SubmitRequest request;
  request.set_mesh_id(mesh_id);
  *request.mutable_options() = options;
  return stub().Submit(&context, request, job);
}

parapm::v1::Job Service::submit(const std::string& mesh_id, const parapm::v1::JobOptions& options) {
  parapm::v1::Job job;
  check_ok(try_submit(mesh_id, options, &job), "submit " + mesh_id);
  return job;
}

grpc::Status Service::try_get_job(const std::string& job_id, parapm::v1::Job* job) {
  grpc::ClientContext context;
  context.set_deadline(deadline_in(seconds(30)));
  rpc::attach_token(context, token_);
  parapm::v1::JobRef ref;
  ref.set_job_id(job_id);
  return stub().GetJob(&context, ref, job);
}

parapm::v1::Job Service::get_job(const std::string& job_id) {
  parapm::v1::Job job;
  check_ok(try_get_job(job_id, &job), "GetJob " + job_id);
  return job;
}

parapm::v1::Job Service::cancel_job(const std::string& job_id) {
  grpc::ClientContext context;
  context.set_deadline(deadline_in(seconds(30)));
  rpc::attach_token(context, token_);
  parapm::v1::JobRef ref;
  ref.set_job_id(job_id);
  parapm::v1::Job job;
  check_ok(stub().CancelJob(&context, ref, &job), "CancelJob " + job_id);
  return job;
}

WatchResult Service::watch(const std::string& job_id, milliseconds timeout,
                           const std::function<void(const parapm::v1::JobEvent&)>& on_event,
                           uint64_t after_seq) {
  grpc::ClientContext context;
  context.set_deadline(deadline_in(timeout));
  rpc::attach_token(context, token_);
  parapm::v1::WatchRequest request;
  request.set_job_id(job_id);
  request.set_after_seq(after_seq);
  WatchResult result;
  auto reader = stub().Watch(&context, request);
  parapm::v1::JobEvent event;
  while (reader->Read(&event)) {
    result.events.push_back(event);
    if (on_event) on_event(event);
  }
  result.status = reader->Finish();
  return result;
}

parapm::v1::Job Service::wait_for_job(const std::string& job_id, milliseconds timeout,
                                      WatchResult* watched) {
  WatchResult result = watch(job_id, timeout);
  if (!result.finished()) {
    std::string seen;
    for (const auto& e : result.events) seen += "  " + describe(e) + "\n";
    throw ServiceError("job " + job_id + " did not end within " + std::to_string(timeout.count()) +
                       " ms (watch: " + status_text(result.status) + "); events:\n" + seen);
  }
  if (watched) *watched = std::move(result);
  return get_job(job_id);
}

grpc::Status Service::try_download(const std::string& job_id, std::string* bytes) {
  grpc::ClientContext context;
  context.set_deadline(deadline_in(seconds(60)));
  rpc::attach_token(context, token_);
  parapm::v1::JobRef ref;
  ref.set_job_id(job_id);
  auto reader = stub().Download(&context, ref);
  parapm::v1::Chunk chunk;
  bytes->clear();
  uint64_t total = 0;
  while (reader->Read(&chunk)) {
    if (chunk.offset() != bytes->size()) {
      context.TryCancel();
      reader->Finish();
      return {grpc::StatusCode::DATA_LOSS, "chunk at offset " + std::to_string(chunk.offset()) +
                                               " after " + std::to_string(bytes->size()) +
                                               " bytes"};
    }
    total = chunk.total();
    bytes->append(chunk.data());
  }
  grpc::Status status = reader->Finish();
  if (status.ok() && total != bytes->size())
    return {grpc::StatusCode::DATA_LOSS,
            "got " + std::to_string(bytes->size()) + " of " + std::to_string(total) + " bytes"};
  return status;
}

std::string Service::download(const std::string& job_id) {
  std::string bytes;
  check_ok(try_download(job_id, &bytes), "Download " + job_id);
  return bytes;
}

}  // namespace parapm::service_test
