// The fixture every service test uses: a fresh folder per test, a Service in it, the
// processes' logs printed when the test failed, every process killed at the end.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <memory>

#include "service_harness.h"
#include "test_support.h"

namespace parapm::service_test {

class ServiceTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() / ("parapm-service-" + std::to_string(::getpid()) + "-" +
                                        info->test_suite_name() + "-" + info->name());
    fs::remove_all(dir_);
    service_ = std::make_unique<Service>(dir_);
  }

  void TearDown() override {
    if (HasFailure()) {
      std::printf("=== logs of %s (kept in %s)\n%s", dir_.filename().c_str(), dir_.c_str(),
                  service_->logs().c_str());
    }
    service_->kill_all();
    service_.reset();
    if (!HasFailure()) fs::remove_all(dir_);
  }

  static fs::path mesh(const std::string& name) { return testing::test_data(name); }

  static parapm::v1::JobOptions options(uint32_t parallelism, parapm::v1::Metric metric,
                                        double ratio, uint64_t seed = 1) {
    parapm::v1::JobOptions o;
    if (parallelism > 0) o.set_parallelism(parallelism);  // 0: left to the coordinator
    o.set_metric(metric);
    if (ratio > 0) o.set_target_ratio(ratio);
    o.set_seed(seed);
    return o;
  }

  // Starts the coordinator with `flags` and `workers` workers named w1, w2, ... and waits
  // until they registered.
  void start(size_t workers, const std::vector<std::string>& flags = {}, unsigned threads = 1) {
    service_->start_coordinator(flags);
    for (size_t i = 1; i <= workers; ++i) {
      std::string name = "w";  // (not "w" + ...: GCC 12 warns falsely, -Wrestrict)
      name += std::to_string(i);
      service_->start_worker(name, threads);
    }
    service_->wait_for_workers(workers);
  }

  // A small good job end to end: upload, build, lossless. The proof the service still serves.
  void expect_serves(uint64_t seed) {
    const fs::path file = mesh("cad-featuretype-3k.stl");
    const auto upload = service().upload_file(file);
    const auto job = service().wait_for_job(
        service()
            .submit(upload.mesh_id(), options(2, parapm::v1::METRIC_QUADRIC, 0.2, seed))
            .job_id(),
        seconds(30));
    ASSERT_EQ(job.state(), parapm::v1::DONE) << job.failure_reason();
    EXPECT_EQ(lossless_failure(service().download(job.job_id()), file, dir()), "");
  }

  Service& service() { return *service_; }
  const fs::path& dir() const { return dir_; }

 private:
  fs::path dir_;
  std::unique_ptr<Service> service_;
};

}  // namespace parapm::service_test
