// The daemons' Prometheus metrics and JSON logs as a monitoring system meets them: a real
// coordinator (metrics at /metrics on its viewer's port) and a real worker
// (--metrics-listen), scraped over loopback while a real job runs and after it ended; the
// counters agree with what the job did; a scrape without the token is refused; with
// --log-format json every log line is one JSON object.
#include <httplib.h>

#include <fstream>
#include <map>
#include <regex>
#include <sstream>

#include <nlohmann/json.hpp>

#include "service_fixture.h"

namespace parapm::service_test {
namespace {

// Prometheus' text format: "name{labels} value" per sample; comments skipped.
std::map<std::string, double> samples(const std::string& text) {
  std::map<std::string, double> out;
  std::istringstream lines(text);
  std::string line;
  while (std::getline(lines, line)) {
    if (line.empty() || line[0] == '#') continue;
    const size_t space = line.rfind(' ');
    out[line.substr(0, space)] = std::stod(line.substr(space + 1));
  }
  return out;
}

// The port in a log line "metrics: http://HOST:PORT/metrics", once the log has it.
int metrics_port_in_log(ChildProcess& process) {
  const std::regex line(R"(metrics: http://[^ ]*:(\d+)/metrics)");
  for (int i = 0; i < 200; ++i) {
    std::smatch found;
    const std::string log = process.log();
    if (std::regex_search(log, found, line)) return std::stoi(found[1]);
    std::this_thread::sleep_for(milliseconds(50));
  }
  return 0;
}

class Metrics : public ServiceTest {
 protected:
  void SetUp() override {
    ServiceTest::SetUp();
    service().set_token("metrics-token");
    service().start_coordinator({"--http", "127.0.0.1:0", "--http-port-file",
                                 (dir() / "http.port").string(), "--log-format", "json"});
    worker_ = &service().start_worker("w1", 1,
                                      {"--metrics-listen", "127.0.0.1:0", "--log-format", "json"});
    service().wait_for_workers(1);
    int port = 0;
    for (int i = 0; i < 200 && port == 0; ++i) {
      std::ifstream in(dir() / "http.port");
      if (!(in >> port)) std::this_thread::sleep_for(milliseconds(50));
    }
    ASSERT_GT(port, 0) << "the viewer's port file did not appear";
    coordinator_ = std::make_unique<httplib::Client>("127.0.0.1", port);
    const int worker_port = metrics_port_in_log(*worker_);
    ASSERT_GT(worker_port, 0) << "the worker did not log its metrics address";
    worker_client_ = std::make_unique<httplib::Client>("127.0.0.1", worker_port);
  }

  static std::map<std::string, double> scrape(httplib::Client& client) {
    const auto response = client.Get("/metrics", {{"Authorization", "Bearer metrics-token"}});
    EXPECT_TRUE(response);
    if (!response) return {};
    EXPECT_EQ(response->status, 200) << response->body;
    EXPECT_EQ(response->get_header_value("Content-Type"),
              "text/plain; version=0.0.4; charset=utf-8");
    return samples(response->body);
  }

  ChildProcess* worker_ = nullptr;
  std::unique_ptr<httplib::Client> coordinator_, worker_client_;
};

TEST_F(Metrics, ScrapedDuringAndAfterARealJobTheyCountWhatHappened) {
  const auto upload = service().upload_file(mesh("cad-cycloidal-43k.ply"));
  parapm::v1::UploadReply refused;
  EXPECT_FALSE(service().try_upload("broken.ply", "ply\nformat nonsense\n", &refused).ok());
  const std::string job_id =
      service().submit(upload.mesh_id(), options(4, parapm::v1::METRIC_ENERGY, 0.05)).job_id();
  // Scraped while the job runs: it shows as running, and the worker's slot as busy.
  bool saw_running = false, saw_worker_busy = false;
  for (int i = 0; i < 3000; ++i) {
    const parapm::v1::JobState state = service().get_job(job_id).state();
    if (state != parapm::v1::QUEUED && state != parapm::v1::RUNNING) break;
    saw_running |= scrape(*coordinator_)["parapm_jobs{state=\"running\"}"] == 1;
    saw_worker_busy |= scrape(*worker_client_)["parapm_worker_subsets_running"] >= 1;
    std::this_thread::sleep_for(milliseconds(10));
  }
  const parapm::v1::Job job = service().wait_for_job(job_id, seconds(120));
  ASSERT_EQ(job.state(), parapm::v1::DONE) << job.failure_reason();
  EXPECT_TRUE(saw_running) << "no scrape saw the job running";
  EXPECT_TRUE(saw_worker_busy) << "no scrape saw the worker's slot busy";

  auto c = scrape(*coordinator_);
  auto w = scrape(*worker_client_);
  EXPECT_EQ(c["parapm_jobs{state=\"done\"}"], 1);
  EXPECT_EQ(c["parapm_jobs{state=\"running\"}"], 0);
  EXPECT_EQ(c["parapm_queue_depth"], 0);
  EXPECT_EQ(c["parapm_workers_registered"], 1);
  EXPECT_EQ(c["parapm_jobs_ended_total{state=\"done\"}"], 1);
  EXPECT_EQ(c["parapm_job_build_seconds_count"], 1);
  EXPECT_GT(c["parapm_job_build_seconds_sum"], 0);
  EXPECT_EQ(c["parapm_job_build_seconds_bucket{le=\"+Inf\"}"], 1);
  EXPECT_EQ(c["parapm_uploads_accepted_total"], 1);
  EXPECT_EQ(c["parapm_uploads_refused_total{reason=\"invalid\"}"], 1);
  EXPECT_EQ(c["parapm_subsets_retried_total"], 0);
  // Every subset ran on the one worker: the two sides agree on what moved.
  EXPECT_GE(c["parapm_subsets_dispatched_total"], 4);
  EXPECT_EQ(w["parapm_worker_subsets_total{outcome=\"done\"}"],
            c["parapm_subsets_dispatched_total"]);
  EXPECT_EQ(w["parapm_worker_subset_seconds_count"], c["parapm_subsets_dispatched_total"]);
  EXPECT_GT(c["parapm_subset_job_bytes_total"], 0);
  EXPECT_EQ(w["parapm_worker_job_bytes_total"], c["parapm_subset_job_bytes_total"]);
  EXPECT_GE(w["parapm_worker_result_bytes_total"], c["parapm_subset_result_bytes_total"]);
  EXPECT_EQ(w["parapm_worker_slots"], 1);
  EXPECT_EQ(w["parapm_worker_subsets_running"], 0);
  // The energy job's points' positions, kept for the build's later jobs.
  EXPECT_GT(w["parapm_worker_held_state_bytes"], 0);
}

// A job cancelled before it started ended too: counted like one cancelled while it ran.
TEST_F(Metrics, AJobCancelledWhileQueuedIsCountedAsEnded) {
  const auto upload = service().upload_file(mesh("cad-cycloidal-43k.ply"));
  std::vector<std::string> ids;
  for (int i = 0; i < 3; ++i)
    ids.push_back(
        service().submit(upload.mesh_id(), options(4, parapm::v1::METRIC_ENERGY, 0.05)).job_id());
  // Two are built at once (--max-running-jobs' default): the third waits in the queue.
  std::string queued;
  for (int i = 0; i < 200 && queued.empty(); ++i) {
    for (const std::string& id : ids)
      if (service().get_job(id).state() == parapm::v1::QUEUED) queued = id;
    if (queued.empty()) std::this_thread::sleep_for(milliseconds(10));
  }
  ASSERT_FALSE(queued.empty()) << "no job waited in the queue";
  service().cancel_job(queued);
  EXPECT_EQ(service().wait_for_job(queued, seconds(10)).state(), parapm::v1::CANCELLED);
  EXPECT_EQ(scrape(*coordinator_)["parapm_jobs_ended_total{state=\"cancelled\"}"], 1);
  double ended = 1;
  for (const std::string& id : ids) {
    if (id == queued) continue;
    service().cancel_job(id);
    const parapm::v1::JobState state = service().wait_for_job(id, seconds(120)).state();
    EXPECT_TRUE(state == parapm::v1::CANCELLED || state == parapm::v1::DONE) << state;
    ++ended;
  }
  const auto c = scrape(*coordinator_);
  EXPECT_EQ(c.at("parapm_jobs_ended_total{state=\"cancelled\"}") +
                c.at("parapm_jobs_ended_total{state=\"done\"}"),
            ended);
  EXPECT_EQ(c.at("parapm_queue_depth"), 0);
}

TEST_F(Metrics, AScrapeWithoutTheTokenIsRefused) {
  for (httplib::Client* client : {coordinator_.get(), worker_client_.get()}) {
    const auto bare = client->Get("/metrics");
    ASSERT_TRUE(bare);
    EXPECT_EQ(bare->status, 401);
    const auto wrong = client->Get("/metrics", {{"Authorization", "Bearer not-it"}});
    ASSERT_TRUE(wrong);
    EXPECT_EQ(wrong->status, 401);
  }
  // Beyond loopback, no token: the worker refuses to start rather than serve metrics openly.
  ChildProcess open_worker(
      "open worker",
      {(fs::path(PARAPM_BINARY_DIR) / "parapm-worker").string(), "--coordinator",
       service().address(), "--listen", "127.0.0.1:0", "--metrics-listen", "0.0.0.0:0"},
      dir() / "open-worker.log");
  const std::optional<int> status = open_worker.wait(seconds(10));
  ASSERT_TRUE(status.has_value()) << "it started";
  EXPECT_TRUE(WIFEXITED(*status) && WEXITSTATUS(*status) == 2) << open_worker.log();
  EXPECT_NE(open_worker.log().find("without a token"), std::string::npos) << open_worker.log();
}

TEST_F(Metrics, JsonLogsAreOneObjectPerLine) {
  // A job whose subsets run on the worker, so that both logs have its lines.
  service().wait_for_job(service()
                             .submit(service().upload_file(mesh("cad-cycloidal-43k.ply")).mesh_id(),
                                     options(2, parapm::v1::METRIC_QUADRIC, 0.2))
                             .job_id(),
                         seconds(60));
  for (ChildProcess* process : {&service().coordinator(), worker_}) {
    std::istringstream lines(process->log());
    std::string line;
    size_t count = 0;
    while (std::getline(lines, line)) {
      const nlohmann::json object = nlohmann::json::parse(line, nullptr, false);
      ASSERT_TRUE(object.is_object()) << process->name() << ": " << line;
      for (const char* key : {"time", "level", "logger", "message"})
        EXPECT_TRUE(object.contains(key)) << process->name() << ": no " << key << " in " << line;
      ++count;
    }
    EXPECT_GT(count, 4u) << process->name();
  }
}

}  // namespace
}  // namespace parapm::service_test
