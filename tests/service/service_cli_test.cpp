// The service through the command-line client, as a user runs it: `parapm up` (a coordinator
// and workers as child processes, stopped by Ctrl-C), `submit`, `jobs`, `watch`, `level`,
// `stream`, `get`, `cancel`; and TLS with a certificate the client verifies.
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "io/mesh_io.h"
#include "service_fixture.h"

namespace parapm::service_test {
namespace {

// A port no one listens on now (bound to 0, read back, released).
int free_port() {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof address);
  socklen_t size = sizeof address;
  getsockname(fd, reinterpret_cast<sockaddr*>(&address), &size);
  close(fd);
  return ntohs(address.sin_port);
}

nlohmann::json json_of(const CliResult& result) {
  // --json prints one object on one line; log lines may surround it.
  std::istringstream lines(result.output);
  std::string line;
  while (std::getline(lines, line))
    if (!line.empty() && line[0] == '{') return nlohmann::json::parse(line);
  ADD_FAILURE() << "no JSON object in:\n" << result.output;
  return {};
}

class ServiceCli : public ServiceTest {
 protected:
  // `parapm up` with `workers` workers, listening on `server`, its data in the test's folder,
  // its viewer on any free port (the default one is the machine's, and tests run side by side).
  std::vector<std::string> up_command(int workers, const std::string& server) {
    return {(fs::path(PARAPM_BINARY_DIR) / "parapm").string(),
            "up",
            "--workers",
            std::to_string(workers),
            "--data",
            (dir() / "up-data").string(),
            "--listen",
            server,
            "--http",
            "127.0.0.1:0"};
  }
};

TEST_F(ServiceCli, UpSubmitFetchStreamAndStopWithCtrlC) {
  const int port = free_port();
  const std::string server = "127.0.0.1:" + std::to_string(port);
  ChildProcess up("up", up_command(2, server), dir() / "up.log");
  // Ready when the coordinator wrote its port and both workers registered.
  for (int i = 0; i < 200 && up.log().find("registered with coordinator") == std::string::npos; ++i)
    std::this_thread::sleep_for(milliseconds(50));
  ASSERT_TRUE(up.running()) << up.log();

  const fs::path input = mesh("stratocaster-9k.ply");
  const fs::path out = dir() / "strat.pm";
  // (The quadric's own floor, 8000 faces a subset, would leave the 9k-face guitar no round.)
  CliResult submitted =
      run_parapm({"submit", input.string(), "--parallel", "3", "--ratio", "0.05",
                  "--min-subset-faces", "2000", "-o", out.string(), "--json", "--server", server},
                 dir());
  ASSERT_EQ(submitted.exit_code, 0) << submitted.output << up.log();
  const nlohmann::json job = json_of(submitted);
  const std::string job_id = job["job_id"];
  EXPECT_EQ(job["state"], "DONE");
  EXPECT_GE(job["client"]["total_seconds"].get<double>(), 0.0);
  EXPECT_EQ(lossless_failure(read_binary(out), input, dir()), "");
  parapm::v1::JobOptions reference = options(3, parapm::v1::METRIC_QUADRIC, 0.05);
  reference.set_min_subset_faces(2000);
  EXPECT_EQ(read_binary(out), reference_pm(input, reference, dir()))
      << "the service's PM differs from parapm simplify --parallel 3";

  CliResult jobs = run_parapm({"jobs", "--json", "--server", server}, dir());
  ASSERT_EQ(jobs.exit_code, 0) << jobs.output;
  EXPECT_EQ(json_of(jobs)["jobs"][0]["job_id"], job_id);

  CliResult watched = run_parapm({"watch", job_id, "--server", server}, dir());
  EXPECT_EQ(watched.exit_code, 0) << watched.output;
  EXPECT_NE(watched.output.find("done: base mesh"), std::string::npos) << watched.output;
  EXPECT_NE(watched.output.find("on worker-"), std::string::npos) << watched.output;

  const fs::path level = dir() / "level.obj";
  CliResult cut = run_parapm(
      {"level", job_id, "--faces", "4000", "-o", level.string(), "--server", server}, dir());
  ASSERT_EQ(cut.exit_code, 0) << cut.output;
  const Mesh level_mesh = read_mesh(level.string());
  EXPECT_LE(level_mesh.face_count(), 4000u);
  EXPECT_GE(level_mesh.face_count(), 3990u);

  const fs::path levels = dir() / "levels";
  CliResult streamed =
      run_parapm({"stream", job_id, "-o", levels.string(), "--json", "--server", server}, dir());
  ASSERT_EQ(streamed.exit_code, 0) << streamed.output;
  const nlohmann::json stream = json_of(streamed);
  EXPECT_EQ(stream["vsplits"], job["vsplits"]);
  ASSERT_GE(stream["levels"].size(), 3u);
  // The last level written is the full mesh: as many faces as the input (after repair).
  EXPECT_EQ(stream["levels"].back()["faces"], job["input_faces"]);

  CliResult missing =
      run_parapm({"get", "job-none", "-o", (dir() / "x.pm").string(), "--server", server}, dir());
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.output.find("NOT_FOUND"), std::string::npos) << missing.output;

  up.signal(SIGINT);
  const std::optional<int> status = up.wait(seconds(15));
  ASSERT_TRUE(status.has_value()) << "parapm up did not stop on SIGINT\n" << up.log();
  EXPECT_TRUE(WIFEXITED(*status) && WEXITSTATUS(*status) == 0) << up.log();
  CliResult after = run_parapm({"jobs", "--server", server}, dir());
  EXPECT_EQ(after.exit_code, 3) << "the coordinator still answers after Ctrl-C: " << after.output;
}

// The processes `pid` has started (/proc/PID/task/PID/children).
std::vector<pid_t> children_of(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/task/" + std::to_string(pid) + "/children");
  std::vector<pid_t> children;
  for (pid_t child = 0; in >> child;) children.push_back(child);
  return children;
}

// Gone, or a zombie left for whoever reaps orphans here.
bool ended(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string stat;
  if (!std::getline(in, stat)) return true;
  const size_t name_end = stat.rfind(')');
  return name_end == std::string::npos || stat.compare(name_end + 2, 1, "Z") == 0;
}

// `parapm up` killed outright (SIGKILL: no chance to stop anything) leaves no coordinator or
// worker behind holding its ports: each child stops when it ends.
TEST_F(ServiceCli, UpKilledLeavesNoDaemonBehind) {
  const std::string server = "127.0.0.1:" + std::to_string(free_port());
  ChildProcess up("up", up_command(2, server), dir() / "up.log");
  for (int i = 0; i < 200 && up.log().find("ParaPM is up") == std::string::npos; ++i)
    std::this_thread::sleep_for(milliseconds(50));
  ASSERT_TRUE(up.running()) << up.log();
  const std::vector<pid_t> children = children_of(up.pid());
  ASSERT_EQ(children.size(), 3u) << "a coordinator and two workers\n" << up.log();
  up.kill_now();
  for (pid_t child : children) {
    for (int i = 0; i < 200 && !ended(child); ++i) std::this_thread::sleep_for(milliseconds(50));
    EXPECT_TRUE(ended(child)) << "process " << child << " outlived parapm up";
    if (!ended(child)) ::kill(child, SIGKILL);
  }
  CliResult after = run_parapm({"jobs", "--server", server}, dir());
  EXPECT_EQ(after.exit_code, 3) << "the coordinator still answers: " << after.output;
}

size_t count_of(const std::string& text, const std::string& what) {
  size_t count = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++count;
  return count;
}

// A worker killed under `parapm up` used to stop the whole service; now it is started again
// and the service keeps building.
TEST_F(ServiceCli, UpStartsACrashedWorkerAgain) {
  const std::string server = "127.0.0.1:" + std::to_string(free_port());
  ChildProcess up("up", up_command(1, server), dir() / "up.log");
  auto wait_for = [&](const std::string& what, size_t count) {
    for (int i = 0; i < 400 && count_of(up.log(), what) < count; ++i)
      std::this_thread::sleep_for(milliseconds(50));
    return count_of(up.log(), what) >= count;
  };
  ASSERT_TRUE(wait_for("registered with coordinator", 1)) << up.log();
  const std::string log = up.log();
  const size_t at = log.find("worker-1 is process ");
  ASSERT_NE(at, std::string::npos) << log;
  const pid_t worker = pid_t(std::stol(log.substr(at + 20)));
  ASSERT_EQ(::kill(worker, SIGKILL), 0);
  ASSERT_TRUE(wait_for("registered with coordinator", 2)) << up.log();
  EXPECT_NE(up.log().find("exited (signal 9); starting it again in 0.5 s"), std::string::npos)
      << up.log();
  ASSERT_TRUE(up.running()) << up.log();

  const fs::path input = mesh("cad-featuretype-3k.stl");
  const fs::path out = dir() / "after-crash.pm";
  CliResult submitted = run_parapm(
      {"submit", input.string(), "--parallel", "2", "-o", out.string(), "--server", server}, dir());
  ASSERT_EQ(submitted.exit_code, 0) << submitted.output << up.log();
  EXPECT_EQ(lossless_failure(read_binary(out), input, dir()), "");
  up.signal(SIGINT);
  const std::optional<int> status = up.wait(seconds(15));
  ASSERT_TRUE(status.has_value()) << up.log();
  EXPECT_TRUE(WIFEXITED(*status) && WEXITSTATUS(*status) == 0) << up.log();
}

TEST_F(ServiceCli, TlsWithAVerifiedCertificate) {
  const std::string cert = testing::test_data("tls/cert.pem");
  const std::string key = testing::test_data("tls/key.pem");
  // No workers: the coordinator runs the subsets itself.
  service().start_coordinator({"--tls-cert", cert, "--tls-key", key, "--local-threads", "2"});
  const std::string server = "localhost:" + std::to_string(service().port());
  const fs::path input = mesh("cad-featuretype-3k.stl");
  const fs::path out = dir() / "tls.pm";
  CliResult submitted = run_parapm({"submit", input.string(), "--parallel", "2", "-o", out.string(),
                                    "--server", server, "--tls", "--tls-ca", cert},
                                   dir());
  ASSERT_EQ(submitted.exit_code, 0) << submitted.output << service().logs();
  EXPECT_EQ(lossless_failure(read_binary(out), input, dir()), "");
  // A client that does not speak TLS gets nowhere.
  CliResult plain = run_parapm({"jobs", "--server", server}, dir());
  EXPECT_EQ(plain.exit_code, 3) << plain.output;
}

}  // namespace
}  // namespace parapm::service_test
