// The coordinator's viewer side (parapm-coordinator --http, server/viewer_http.h) as a browser
// or a script meets it: a real coordinator process, a real HTTP client on loopback. The page
// and its scripts are served; the job list and a job's .pm (the bytes the gRPC download gives)
// need the token; bad ids, unknown jobs and unknown routes get JSON errors with their status;
// beyond loopback the coordinator refuses to start the viewer without a token. (The page itself
// runs in a real browser in viewer/test/browser.test.mjs.)
#include <httplib.h>

#include <fstream>

#include "service_fixture.h"

namespace parapm::service_test {
namespace {

class ViewerHttp : public ServiceTest {
 protected:
  // A coordinator with its viewer, running subsets itself, with a token.
  void start_with_viewer() {
    service().set_token("viewer-token");
    start(0, {"--local-threads", "2", "--http", "127.0.0.1:0", "--http-port-file",
              (dir() / "viewer.port").string()});
    int port = 0;
    for (int i = 0; i < 200 && port == 0; ++i) {
      std::ifstream in(dir() / "viewer.port");
      if (!(in >> port)) std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    ASSERT_GT(port, 0) << "the viewer's port file did not appear";
    client_ = std::make_unique<httplib::Client>("127.0.0.1", port);
    client_->set_read_timeout(std::chrono::seconds(30));
  }

  httplib::Result get(const std::string& path, const std::string& token = "viewer-token") {
    httplib::Headers headers;
    if (!token.empty()) headers.emplace("Authorization", "Bearer " + token);
    return client_->Get(path, headers);
  }

  std::string done_job() {
    const auto upload = service().upload_file(mesh("cad-featuretype-3k.stl"));
    const auto job = service().wait_for_job(
        service().submit(upload.mesh_id(), options(2, parapm::v1::METRIC_QUADRIC, 0.2)).job_id(),
        seconds(30));
    EXPECT_EQ(job.state(), parapm::v1::DONE) << job.failure_reason();
    return job.job_id();
  }

  std::unique_ptr<httplib::Client> client_;
};

TEST_F(ViewerHttp, ServesThePageTheJobsAndTheirPms) {
  start_with_viewer();
  const std::string job_id = done_job();

  const auto page = get("/", "");  // the page needs no token: its data does
  ASSERT_TRUE(page);
  EXPECT_EQ(page->status, 200);
  EXPECT_NE(page->body.find("<title>ParaPM viewer</title>"), std::string::npos);
  EXPECT_EQ(page->get_header_value("X-Content-Type-Options"), "nosniff");
  for (const char* script : {"/viewer.js", "/pm_decoder.js", "/pm_mesh.js", "/renderer.js"}) {
    const auto file = get(script, "");
    ASSERT_TRUE(file) << script;
    EXPECT_EQ(file->status, 200) << script;
    EXPECT_EQ(file->get_header_value("Content-Type"), "text/javascript; charset=utf-8");
  }

  const auto jobs = get("/api/jobs");
  ASSERT_TRUE(jobs);
  EXPECT_EQ(jobs->status, 200);
  EXPECT_NE(jobs->body.find("\"job_id\":\"" + job_id + "\""), std::string::npos) << jobs->body;
  EXPECT_NE(jobs->body.find("\"state\":\"DONE\""), std::string::npos) << jobs->body;

  const auto pm = get("/api/jobs/" + job_id + "/pm");
  ASSERT_TRUE(pm);
  EXPECT_EQ(pm->status, 200);
  EXPECT_EQ(pm->body, service().download(job_id));
  EXPECT_EQ(pm->get_header_value("X-ParaPM-Vsplits"),
            std::to_string(service().get_job(job_id).vsplits()));
  // The token may come as a query parameter too (a page's link cannot carry headers).
  const auto by_query = client_->Get("/api/jobs/" + job_id + "?token=viewer-token");
  ASSERT_TRUE(by_query);
  EXPECT_EQ(by_query->status, 200);
}

TEST_F(ViewerHttp, BadRequestsGetJsonErrorsWithTheirStatus) {
  start_with_viewer();
  const std::string job_id = done_job();
  struct Case {
    std::string path, token;
    int status;
    std::string says;
  };
  const std::vector<Case> cases = {
      {"/api/jobs", "", 401, "needs a token"},
      {"/api/jobs/" + job_id + "/pm", "wrong", 401, "not this coordinator's"},
      {"/api/jobs/job-0000000000000000/pm", "viewer-token", 404, "no job"},
      {"/api/jobs/job-0000000000000000", "viewer-token", 404, "no job"},
      {"/api/jobs/bad%20id/pm", "viewer-token", 400, "is not a job id"},
      {"/api/nothing", "viewer-token", 404, "no such route"},
      {"/nothing.js", "", 404, "no such file"},
  };
  for (const Case& c : cases) {
    const auto response = get(c.path, c.token);
    ASSERT_TRUE(response) << c.path;
    EXPECT_EQ(response->status, c.status) << c.path << ": " << response->body;
    EXPECT_EQ(response->get_header_value("Content-Type"), "application/json") << c.path;
    EXPECT_NE(response->body.find("\"error\": \""), std::string::npos) << response->body;
    EXPECT_NE(response->body.find(c.says), std::string::npos) << c.path << ": " << response->body;
  }
  // A request with a body is refused, not read.
  const auto posted = client_->Post("/api/jobs", std::string(100000, 'x'), "text/plain");
  ASSERT_TRUE(posted);
  EXPECT_GE(posted->status, 400);
  // The service goes on.
  expect_serves(2);
}

// parapm view JOB: the job's page address, its token in the fragment (never sent to a server);
// an unknown job is an error, not an address.
TEST_F(ViewerHttp, ParapmViewPrintsTheJobsAddress) {
  start_with_viewer();
  const std::string job_id = done_job();
  write_binary(dir() / "token", "viewer-token\n");
  const std::vector<std::string> connection = {"--server", service().address(), "--token-file",
                                               (dir() / "token").string(), "--no-open"};
  std::vector<std::string> args = {"view", job_id, "--viewer", "http://127.0.0.1:1234/"};
  args.insert(args.end(), connection.begin(), connection.end());
  const CliResult shown = run_parapm(args, dir());
  EXPECT_EQ(shown.exit_code, 0) << shown.output;
  EXPECT_NE(shown.output.find("http://127.0.0.1:1234/#job=" + job_id + "&token=viewer-token"),
            std::string::npos)
      << shown.output;
  args[1] = "job-0000000000000000";
  const CliResult unknown = run_parapm(args, dir());
  EXPECT_NE(unknown.exit_code, 0);
  EXPECT_NE(unknown.output.find("no job"), std::string::npos) << unknown.output;
}

// With the coordinator's certificate the viewer is HTTPS, verified against it; plain HTTP to it
// gets nothing.
TEST_F(ViewerHttp, ServesHttpsWithTheCoordinatorsCertificate) {
  const std::string cert = testing::test_data("tls/cert.pem");
  const std::string key = testing::test_data("tls/key.pem");
  service().start_coordinator({"--tls-cert", cert, "--tls-key", key, "--local-threads", "2",
                               "--http", "127.0.0.1:0", "--http-port-file",
                               (dir() / "viewer.port").string()});
  int port = 0;
  for (int i = 0; i < 200 && port == 0; ++i) {
    std::ifstream in(dir() / "viewer.port");
    if (!(in >> port)) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ASSERT_GT(port, 0);
  httplib::SSLClient secure("localhost", port);
  secure.set_ca_cert_path(cert.c_str());
  secure.enable_server_certificate_verification(true);
  const auto jobs = secure.Get("/api/jobs");
  ASSERT_TRUE(jobs) << httplib::to_string(jobs.error());
  EXPECT_EQ(jobs->status, 200);
  EXPECT_NE(jobs->body.find("\"jobs\""), std::string::npos);
  httplib::Client plain("127.0.0.1", port);
  plain.set_read_timeout(std::chrono::seconds(5));
  const auto refused = plain.Get("/api/jobs");
  EXPECT_TRUE(!refused || refused->status >= 400);
}

TEST_F(ViewerHttp, BeyondLoopbackTheViewerNeedsAToken) {
  ChildProcess coordinator(
      "coordinator",
      {(fs::path(PARAPM_BINARY_DIR) / "parapm-coordinator").string(), "--listen", "127.0.0.1:0",
       "--data", (dir() / "data").string(), "--http", "0.0.0.0:0"},
      dir() / "refused.log");
  const auto status = coordinator.wait(seconds(20));
  ASSERT_TRUE(status.has_value()) << "it kept running";
  EXPECT_TRUE(WIFEXITED(*status) && WEXITSTATUS(*status) == 2) << coordinator.log();
  EXPECT_NE(coordinator.log().find("without a token"), std::string::npos) << coordinator.log();
}

}  // namespace
}  // namespace parapm::service_test
