// parapm jobs / watch JOB / cancel JOB / delete JOB | --mesh MESH: the coordinator's job list,
// one job's events as they happen, cancellation, and deletion.
#include <ctime>

#include <spdlog/spdlog.h>

#include "cli_common.h"
#include "commands.h"
#include "service_client.h"
#include "service_json.h"

namespace parapm::cli {
namespace {

struct JobsArgs {
  ConnectionArgs connection;
  uint32_t limit = 20;
  std::string job_id;
  std::string mesh_id;  // delete --mesh
  bool json = false;
};

std::string local_time(int64_t unix_ms) {
  const std::time_t t = std::time_t(unix_ms / 1000);
  std::tm tm{};
  localtime_r(&t, &tm);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%d %H:%M:%S", &tm);
  return text;
}

int run_jobs(const JobsArgs& args) {
  ServiceClient client(args.connection);
  parapm::v1::ListJobsRequest request;
  request.set_limit(args.limit);
  parapm::v1::ListJobsReply reply;
  auto context = client.context();
  check_status(client.stub().ListJobs(context.get(), request, &reply), "list jobs",
               client.server());
  if (args.json) {
    nlohmann::json jobs = nlohmann::json::array();
    for (const auto& job : reply.jobs()) jobs.push_back(job_json(job));
    print_json({{"jobs", jobs}});
    return 0;
  }
  std::printf("%-21s %-9s %-19s %10s %10s %9s  %s\n", "job", "state", "created", "faces", "base",
              "seconds", "mesh");
  for (const auto& job : reply.jobs()) {
    std::string state = job_state_name(job.state());
    if (job.state() == parapm::v1::RUNNING && job.progress_total() > 0)
      state += " " + std::to_string(job.progress_done() * 100 / job.progress_total()) + "%";
    std::printf("%-21s %-9s %-19s %10llu %10llu %9.2f  %s%s%s\n", job.job_id().c_str(),
                state.c_str(), local_time(job.created_unix_ms()).c_str(),
                (unsigned long long)job.input_faces(), (unsigned long long)job.base_faces(),
                job.seconds(), job.mesh_id().c_str(), job.failure_reason().empty() ? "" : "  ",
                job.failure_reason().c_str());
  }
  return 0;
}

int run_watch(const JobsArgs& args) {
  ServiceClient client(args.connection);
  const parapm::v1::Job job = client.watch(args.job_id, [&](const parapm::v1::JobEvent& event) {
    if (args.json) {
      nlohmann::json line = message_json(event);
      std::printf("%s\n", line.dump().c_str());
    } else {
      std::printf("%s  %s\n", local_time(event.unix_ms()).c_str(), describe_event(event).c_str());
    }
    std::fflush(stdout);
  });
  return job.state() == parapm::v1::DONE ? 0 : 1;
}

int run_cancel(const JobsArgs& args) {
  ServiceClient client(args.connection);
  parapm::v1::JobRef ref;
  ref.set_job_id(args.job_id);
  parapm::v1::Job job;
  auto context = client.context();
  check_status(client.stub().CancelJob(context.get(), ref, &job), "cancel " + args.job_id,
               client.server());
  if (args.json)
    print_json(job_json(job));
  else
    std::printf("job %s: %s%s\n", job.job_id().c_str(), job_state_name(job.state()),
                job.state() == parapm::v1::RUNNING ? " (stopping)" : "");
  return 0;
}

int run_delete(const JobsArgs& args) {
  if (args.job_id.empty() == args.mesh_id.empty())
    throw_invalid("give a job id or --mesh MESH (one of them)");
  ServiceClient client(args.connection);
  parapm::v1::DeleteReply reply;
  auto context = client.context();
  if (!args.mesh_id.empty()) {
    parapm::v1::MeshRef ref;
    ref.set_mesh_id(args.mesh_id);
    check_status(client.stub().DeleteMesh(context.get(), ref, &reply),
                 "delete mesh " + args.mesh_id, client.server());
  } else {
    parapm::v1::JobRef ref;
    ref.set_job_id(args.job_id);
    check_status(client.stub().DeleteJob(context.get(), ref, &reply), "delete " + args.job_id,
                 client.server());
  }
  if (args.json)
    print_json(message_json(reply));
  else
    std::printf("deleted %llu jobs, %llu meshes; %llu blobs (%llu bytes) freed\n",
                static_cast<unsigned long long>(reply.jobs_deleted()),
                static_cast<unsigned long long>(reply.meshes_deleted()),
                static_cast<unsigned long long>(reply.blobs_removed()),
                static_cast<unsigned long long>(reply.bytes_freed()));
  return 0;
}

}  // namespace

void add_jobs_commands(CLI::App& app, int& exit_code) {
  auto jobs = std::make_shared<JobsArgs>();
  CLI::App* list = app.add_subcommand("jobs", "list the coordinator's jobs, newest first");
  list->add_option("--limit", jobs->limit, "at most this many")->capture_default_str();
  list->add_flag("--json", jobs->json, "one JSON object {\"jobs\": [...]}");
  add_connection_options(list, jobs->connection);
  list->callback([jobs, &exit_code] { exit_code = run_jobs(*jobs); });

  auto watch = std::make_shared<JobsArgs>();
  CLI::App* w = app.add_subcommand(
      "watch",
      "print a job's events (queued, rounds, subsets and their workers, merges) until "
      "it ends; exit 0 when it is done, 1 when it failed or was cancelled");
  w->add_option("job", watch->job_id, "job id")->required();
  w->add_flag("--json", watch->json, "one JSON object per event and line");
  add_connection_options(w, watch->connection);
  w->callback([watch, &exit_code] { exit_code = run_watch(*watch); });

  auto cancel = std::make_shared<JobsArgs>();
  CLI::App* c =
      app.add_subcommand("cancel",
                         "cancel a job: a queued job at once, a running one at its next check (its "
                         "workers stop within a second)");
  c->add_option("job", cancel->job_id, "job id")->required();
  c->add_flag("--json", cancel->json, "print the job as one JSON object");
  add_connection_options(c, cancel->connection);
  c->callback([cancel, &exit_code] { exit_code = run_cancel(*cancel); });

  auto remove = std::make_shared<JobsArgs>();
  CLI::App* d = app.add_subcommand(
      "delete",
      "delete an ended job (its events and PM), or with --mesh a mesh and all its jobs; the "
      "stored files no job or mesh names any more are removed (a queued or running job: cancel "
      "it first)");
  d->add_option("job", remove->job_id, "job id");
  d->add_option("--mesh", remove->mesh_id, "delete this mesh and its jobs instead");
  d->add_flag("--json", remove->json, "print what was deleted as one JSON object");
  add_connection_options(d, remove->connection);
  d->callback([remove, &exit_code] { exit_code = run_delete(*remove); });
}

}  // namespace parapm::cli
