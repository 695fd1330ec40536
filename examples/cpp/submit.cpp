// parapm-example-submit SERVER MESH OUT.pm: uploads MESH to the coordinator at SERVER (token:
// PARAPM_TOKEN when it needs one), builds its PM there (quadric, base mesh at 2%), prints the
// job's events as they come and downloads the PM to OUT.pm.
#include <cstdio>

#include <parapm/client.h>

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: %s SERVER MESH OUT.pm\n", argv[0]);
    return 2;
  }
  try {
    parapm::client::ServiceClient service({.server = argv[1]});
    const parapm::v1::UploadReply mesh = service.upload(argv[2]);
    parapm::v1::JobOptions options;
    options.set_metric(parapm::v1::METRIC_QUADRIC);
    options.set_target_ratio(0.02);
    const parapm::v1::Job submitted = service.submit(mesh.mesh_id(), options);
    const parapm::v1::Job job =
        service.watch(submitted.job_id(), [](const parapm::v1::JobEvent& event) {
          std::printf("%s\n", parapm::client::describe_event(event).c_str());
        });
    if (job.state() != parapm::v1::DONE) {
      std::fprintf(stderr, "job %s: %s\n", job.job_id().c_str(), job.failure_reason().c_str());
      return 1;
    }
    service.download(job.job_id(), argv[3]);
    std::printf("%s: %llu vsplits in %s\n", job.job_id().c_str(),
                static_cast<unsigned long long>(job.vsplits()), argv[3]);
    return 0;
  } catch (const parapm::Error& e) {
    std::fprintf(stderr, "parapm-example-submit: %s\n", e.what());
    return 2;
  }
}
