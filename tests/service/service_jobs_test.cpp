// The service doing its job, with real processes on loopback: a coordinator and workers build
// the same .pm as `parapm simplify --parallel P` (byte for byte, lossless), many jobs at once
// all complete, a done PM streams as vsplit batches a PmReader decodes, levels come out as
// meshes, and the standard gRPC health check answers.
#include <signal.h>
#include <sys/wait.h>

#include <map>
#include <set>
#include <sstream>
#include <thread>

#include <grpcpp/generic/generic_stub.h>

#include "io/mesh_io.h"
#include "parallel/parallel_build.h"
#include "pm/levels.h"
#include "pm/pm_file.h"
#include "rpc_security.h"
#include "service_fixture.h"

namespace parapm::service_test {
namespace {

using parapm::v1::JobEvent;

// The events of one job tell a consistent story: seq from 1 without gaps, queued first, one
// "started" per attempt, each round partitioned, its subsets started and done, merged, and
// the job's end last.
void expect_consistent_events(const WatchResult& watched, const parapm::v1::Job& job) {
  ASSERT_TRUE(watched.finished()) << status_text(watched.status);
  const auto& events = watched.events;
  for (size_t i = 0; i < events.size(); ++i) {
    EXPECT_EQ(events[i].seq(), i + 1) << describe(events[i]);
    EXPECT_EQ(events[i].job_id(), job.job_id());
  }
  EXPECT_TRUE(events.front().has_queued()) << describe(events.front());
  std::map<uint32_t, uint32_t> subsets_of_round;
  std::map<uint32_t, std::set<uint32_t>> done_of_round;
  size_t started = 0, merged = 0;
  for (const JobEvent& e : events) {
    if (e.has_started()) {
      ++started;
      EXPECT_EQ(e.started().input_faces(), job.input_faces());
    }
    if (e.has_partitioned()) subsets_of_round[e.partitioned().round()] = e.partitioned().subsets();
    if (e.has_subset_done())
      done_of_round[e.subset_done().round()].insert(e.subset_done().subset());
    if (e.has_merged()) ++merged;
  }
  EXPECT_EQ(started, job.attempts());
  EXPECT_FALSE(subsets_of_round.empty());
  EXPECT_EQ(merged, subsets_of_round.size());
  for (const auto& [round, subsets] : subsets_of_round)
    EXPECT_EQ(done_of_round[round].size(), subsets) << "round " << round;
  const JobEvent& last = events.back();
  ASSERT_TRUE(last.has_finished()) << describe(last);
  EXPECT_EQ(last.finished().pm_sha256(), job.pm_sha256());
  EXPECT_EQ(last.finished().base_faces(), job.base_faces());
  EXPECT_EQ(last.finished().vsplits(), job.vsplits());
}

class ServiceJobs : public ServiceTest {
 protected:
  // Uploads `file`, builds with `options`, and checks the job, its events and its PM against
  // the in-process build. Returns the PM.
  std::string build_and_compare(const std::string& file, const parapm::v1::JobOptions& options,
                                const std::set<std::string>& worker_names,
                                WatchResult* events = nullptr) {
    const parapm::v1::UploadReply upload = service().upload_file(mesh(file));
    EXPECT_GT(upload.faces(), 0u);
    EXPECT_EQ(upload.content_sha256().size(), 64u);
    const parapm::v1::Job submitted = service().submit(upload.mesh_id(), options);
    EXPECT_EQ(submitted.state(), parapm::v1::QUEUED);
    EXPECT_EQ(submitted.mesh_id(), upload.mesh_id());
    WatchResult watched;
    const parapm::v1::Job job = service().wait_for_job(submitted.job_id(), seconds(60), &watched);
    EXPECT_EQ(job.state(), parapm::v1::DONE) << job.failure_reason();
    EXPECT_EQ(job.attempts(), 1u);
    EXPECT_EQ(job.input_faces(), upload.faces());
    expect_consistent_events(watched, job);
    for (const JobEvent& e : watched.events)
      if (e.has_subset_started()) {
        EXPECT_TRUE(worker_names.count(e.subset_started().worker())) << describe(e);
      }

    const std::string pm = service().download(job.job_id());
    EXPECT_EQ(pm.size(), job.pm_bytes());
    const std::string expected = reference_pm(mesh(file), options, dir());
    EXPECT_TRUE(pm == expected) << file << ": the service's PM (" << pm.size()
                                << " bytes) differs from parapm simplify's (" << expected.size()
                                << " bytes)";
    EXPECT_EQ(lossless_failure(pm, mesh(file), dir()), "");
    if (events) *events = std::move(watched);
    return pm;
  }
};

TEST_F(ServiceJobs, ThreeWorkersBuildTheInProcessPm) {
  start(3);
  const std::set<std::string> names = {"w1", "w2", "w3"};
  // (The quadric's own floor, 8000 faces a subset, would leave the 9k-face guitar no round.)
  parapm::v1::JobOptions guitar = options(4, parapm::v1::METRIC_QUADRIC, 0.05, 7);
  guitar.set_min_subset_faces(2000);
  build_and_compare("stratocaster-9k.ply", guitar, names);
  // The job took the mesh its upload had parsed (UploadHandoff), not the blob again.
  EXPECT_NE(service().coordinator().log().find("the mesh as parsed at its upload"),
            std::string::npos);
  // The energy metric's state (points, curves, wedge classes) travels in the subset jobs;
  // the airplane has colours, so the wedge changes do too. So does its tuning, here not the
  // defaults: `--star-planes-weight 3 --volume-weight 0 --spring-scale 0.01
  // --crease-min-edges 2 --crease-min-length 0.02`.
  parapm::v1::JobOptions tuned = options(4, parapm::v1::METRIC_ENERGY, 0.02, 3);
  parapm::v1::EnergyTuning& tuning = *tuned.mutable_energy();
  tuning.set_star_planes_weight(3);
  tuning.set_volume_weight(0);
  tuning.set_spring_scale(0.01);
  tuning.set_min_crease_edges(2);
  tuning.set_crease_min_length(0.02);
  build_and_compare("pymeshlab-colored-airplane-11k.ply", tuned, names);
  // Extra rounds past the handover (the vessel gets two with a floor of 200 faces a subset),
  // and rounds bounded by a tighter border band, as `parapm simplify --extra-round-faces 200
  // --border-excess 0.02` builds them.
  parapm::v1::JobOptions extra = options(2, parapm::v1::METRIC_QUADRIC, 0.005);
  extra.set_extra_round_faces(200);
  extra.set_border_excess(0.02);
  build_and_compare("gmsh-aneurysm-20k.stl.gz", extra, names);
  // The repair's copies freed (`--free-copies`): the CAD part's non-manifold vertices.
  parapm::v1::JobOptions free_copies = options(2, parapm::v1::METRIC_QUADRIC, 0);
  free_copies.set_free_copies(true);
  build_and_compare("cad-cycloidal-43k.ply", free_copies, names);
  // The quadric's volume and border kept at every level (`--quadric-placement constrained`).
  parapm::v1::JobOptions constrained = options(2, parapm::v1::METRIC_QUADRIC, 0.02);
  constrained.set_quadric_placement(parapm::v1::QUADRIC_PLACEMENT_CONSTRAINED);
  build_and_compare("gmsh-aneurysm-20k.stl.gz", constrained, names);
  // Every component kept (`--keep-components`), on the guitar's many parts.
  parapm::v1::JobOptions kept = options(2, parapm::v1::METRIC_ENERGY, 0);
  kept.set_keep_components(true);
  build_and_compare("stratocaster-9k.ply", kept, names);
  // At p = 12 the 20k-face vessel's rounds take at most one subset per 8000 faces (the
  // quadric's default, as `parapm simplify` builds it: 2 in round 0), or 12 in every round
  // with `--min-subset-faces 0`.
  const uint64_t floor = subset_faces_by_metric(false);
  for (const bool no_floor : {false, true}) {
    parapm::v1::JobOptions capped = options(12, parapm::v1::METRIC_QUADRIC, 0.01);
    if (no_floor) capped.set_min_subset_faces(0);
    WatchResult watched;
    build_and_compare("gmsh-aneurysm-20k.stl.gz", capped, names, &watched);
    size_t rounds = 0;
    for (const JobEvent& e : watched.events) {
      if (!e.has_partitioned()) continue;
      const auto& partitioned = e.partitioned();
      if (no_floor) {
        EXPECT_EQ(partitioned.subsets(), 12u) << describe(e);
      } else {
        EXPECT_LE(partitioned.subsets(), partitioned.faces() / floor) << describe(e);
        if (partitioned.round() == 0) {
          EXPECT_EQ(partitioned.subsets(), 2u) << describe(e);
        }
      }
      ++rounds;
    }
    EXPECT_GT(rounds, 0u);
  }

  // The same bytes again: the same mesh.
  const auto first = service().upload_file(mesh("stratocaster-9k.ply"));
  const auto again = service().upload_file(mesh("stratocaster-9k.ply"));
  EXPECT_EQ(first.mesh_id(), again.mesh_id());
  EXPECT_EQ(first.content_sha256(), again.content_sha256());
}

// A build's workers keep state between rounds (a quadric job's quadrics, an energy job's
// points' positions: held_state.h), and later jobs go to them without it: the PM stays the
// in-process build's. w2 keeps none (--held-state-mb 0), as after a restart or an eviction:
// the jobs left for it come back refused and go whole, and no job of the build leaves state
// out for it again.
TEST_F(ServiceJobs, WorkersKeepTheirStateBetweenRounds) {
  service().start_coordinator({});
  service().start_worker("w1", 1);
  service().start_worker("w2", 1, {"--held-state-mb", "0"});
  service().wait_for_workers(2);
  size_t refusals_before = 0;
  for (const auto metric : {parapm::v1::METRIC_QUADRIC, parapm::v1::METRIC_ENERGY}) {
    parapm::v1::JobOptions options = ServiceTest::options(4, metric, 0.01);
    options.set_min_subset_faces(0);
    WatchResult watched;
    build_and_compare("gmsh-aneurysm-20k.stl.gz", options, {"w1", "w2"}, &watched);
    ASSERT_TRUE(watched.finished());
    const auto& transport = watched.events.back().finished().transport();
    EXPECT_GT(transport.held_items(), 0u) << metric;
    EXPECT_GT(transport.sent_items(), 0u) << metric;
    const std::string log = service().coordinator().log();
    size_t refusals = 0;
    for (size_t at = log.find("lacks the state"); at != std::string::npos;
         at = log.find("lacks the state", at + 1))
      ++refusals;
    // Refused once, w2 is left nothing out again: at most its two calls in flight refused.
    EXPECT_GT(refusals, refusals_before) << metric << log;
    EXPECT_LE(refusals, refusals_before + 2) << metric << log;
    refusals_before = refusals;
  }
}

// Eight clients at once, each uploading and submitting from its own thread (two per mesh,
// so identical uploads race too): every job completes and every PM is lossless.
TEST_F(ServiceJobs, EightConcurrentJobsAllComplete) {
  start(3);
  const std::vector<std::string> files = {"stratocaster-9k.ply", "cad-featuretype-3k.stl",
                                          "pymeshlab-colored-airplane-11k.ply",
                                          "pymeshlab-bunny-textured-10k.obj"};
  constexpr size_t kJobs = 8;
  // Rounds on the workers: the quadric's own floor (8000 faces a subset) would leave these
  // meshes of 3k-11k faces none.
  auto job_options = [](size_t i) {
    parapm::v1::JobOptions o = options(2 + uint32_t(i % 3), parapm::v1::METRIC_QUADRIC, 0.1);
    o.set_min_subset_faces(2000);
    return o;
  };
  struct Outcome {
    std::string mesh_id, job_id, error;
    parapm::v1::Job job;
  };
  std::vector<Outcome> outcomes(kJobs);
  std::vector<std::thread> clients;
  for (size_t i = 0; i < kJobs; ++i)
    clients.emplace_back([&, i] {
      try {
        const auto upload = service().upload_file(mesh(files[i % files.size()]));
        outcomes[i].mesh_id = upload.mesh_id();
        const auto job = service().submit(upload.mesh_id(), job_options(i));
        outcomes[i].job_id = job.job_id();
        outcomes[i].job = service().wait_for_job(job.job_id(), seconds(90));
      } catch (const std::exception& e) {
        outcomes[i].error = e.what();
      }
    });
  for (std::thread& t : clients) t.join();
  for (size_t i = 0; i < kJobs; ++i) {
    SCOPED_TRACE("client " + std::to_string(i) + ", " + files[i % files.size()]);
    ASSERT_EQ(outcomes[i].error, "");
    EXPECT_EQ(outcomes[i].job.state(), parapm::v1::DONE) << outcomes[i].job.failure_reason();
    const std::string pm = service().download(outcomes[i].job_id);
    EXPECT_EQ(lossless_failure(pm, mesh(files[i % files.size()]), dir()), "");
    const auto reference = reference_pm(mesh(files[i % files.size()]), job_options(i), dir());
    EXPECT_TRUE(pm == reference) << "differs from parapm simplify";
  }
  // The proto's promise: the same bytes uploaded twice give the same mesh id, also when the
  // two uploads overlap.
  for (size_t i = 0; i + files.size() < kJobs; ++i)
    EXPECT_EQ(outcomes[i].mesh_id, outcomes[i + files.size()].mesh_id)
        << files[i] << " uploaded concurrently by two clients got two mesh ids";

  grpc::ClientContext context;
  rpc::attach_token(context, service().token());
  parapm::v1::ListJobsRequest request;
  parapm::v1::ListJobsReply reply;
  ASSERT_TRUE(service().stub().ListJobs(&context, request, &reply).ok());
  EXPECT_EQ(reply.jobs_size(), int(kJobs));
  for (const auto& job : reply.jobs()) EXPECT_EQ(job.state(), parapm::v1::DONE) << job.job_id();
}

struct Streamed {
  grpc::Status status;
  std::vector<parapm::v1::PmStreamMessage> messages;
  std::string bytes;     // the messages' payloads, concatenated
  uint64_t records = 0;  // vsplit records in them
};

Streamed stream_pm(Service& service, const parapm::v1::StreamRequest& request) {
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + seconds(30));
  rpc::attach_token(context, service.token());
  auto reader = service.stub().StreamPM(&context, request);
  Streamed out;
  parapm::v1::PmStreamMessage message;
  while (reader->Read(&message)) {
    out.messages.push_back(message);
    if (message.has_header_and_base()) out.bytes += message.header_and_base();
    if (message.has_vsplit_batch()) {
      out.bytes += message.vsplit_batch();
      out.records += message.count();
    }
  }
  out.status = reader->Finish();
  return out;
}

// Where each split's record begins in a whole .pm (offsets[i]: split i; offsets[n]: the tail).
std::vector<uint64_t> split_offsets(const std::string& pm) {
  std::istringstream in(pm);
  PmReader reader(in, "download");
  reader.read_base();
  std::vector<uint64_t> offsets = {reader.offset()};
  PmSplitRecord record;
  while (reader.next_split(record)) offsets.push_back(reader.offset());
  return offsets;
}

// Decodes `bytes` (header, base, `splits` records) as a viewer does; returns the positions at
// the last level read.
std::vector<Vec3> decode_partial(const std::string& bytes, uint64_t splits, size_t* base_faces) {
  std::istringstream in(bytes);
  PmReader reader(in, "stream", PmReader::Input::kPartialStream);
  *base_faces = reader.read_base().face_count();
  PmSplitRecord record;
  for (uint64_t i = 0; i < splits; ++i)
    if (!reader.next_split(record))
      throw ServiceError("the stream ended at split " + std::to_string(i) + " of " +
                         std::to_string(splits));
  return reader.positions();
}

std::vector<Vec3> positions_at(const std::string& pm, uint64_t level) {
  std::istringstream in(pm);
  PmReader reader(in, "download");
  reader.read_base();
  PmSplitRecord record;
  for (uint64_t i = 0; i < level; ++i) reader.next_split(record);
  return reader.positions();
}

TEST_F(ServiceJobs, StreamPmAndLevels) {
  start(1, {}, 2);
  const auto upload = service().upload_file(mesh("pymeshlab-bunny-textured-10k.obj"));
  const auto submitted =
      service().submit(upload.mesh_id(), options(2, parapm::v1::METRIC_QUADRIC, 0.1));
  const parapm::v1::Job job = service().wait_for_job(submitted.job_id(), seconds(60));
  ASSERT_EQ(job.state(), parapm::v1::DONE) << job.failure_reason();
  const std::string pm = service().download(job.job_id());
  const std::vector<uint64_t> offsets = split_offsets(pm);
  const uint64_t n = job.vsplits();
  ASSERT_EQ(offsets.size(), n + 1);
  ASSERT_GT(n, 100u);

  // The whole stream from the start: the file's bytes up to the tail, in order.
  parapm::v1::StreamRequest request;
  request.set_job_id(job.job_id());
  request.set_batch_vsplits(500);
  const Streamed whole = stream_pm(service(), request);
  ASSERT_TRUE(whole.status.ok()) << status_text(whole.status);
  ASSERT_FALSE(whole.messages.empty());
  EXPECT_TRUE(whole.messages[0].has_header_and_base());
  EXPECT_EQ(whole.messages[0].header_and_base().size(), offsets[0]);
  uint64_t next = 0;
  for (size_t i = 1; i < whole.messages.size(); ++i) {
    const auto& m = whole.messages[i];
    EXPECT_TRUE(m.has_vsplit_batch()) << "message " << i;
    EXPECT_EQ(m.first_vsplit(), next) << "message " << i;
    EXPECT_LE(m.count(), 500u);
    EXPECT_EQ(m.total_vsplits(), n);
    next += m.count();
  }
  EXPECT_EQ(whole.records, n);
  EXPECT_TRUE(whole.bytes == pm.substr(0, offsets[n])) << "the stream is not the file's prefix";
  size_t base_faces = 0;
  EXPECT_EQ(decode_partial(whole.bytes, n, &base_faces), positions_at(pm, n));
  EXPECT_EQ(base_faces, job.base_faces());

  // Resumed from the middle: the rest of the records, no base.
  const uint64_t middle = n / 2;
  request.set_from_vsplit(middle);
  const Streamed rest = stream_pm(service(), request);
  ASSERT_TRUE(rest.status.ok()) << status_text(rest.status);
  ASSERT_FALSE(rest.messages.empty());
  EXPECT_FALSE(rest.messages[0].has_header_and_base());
  EXPECT_EQ(rest.messages[0].first_vsplit(), middle);
  EXPECT_EQ(rest.records, n - middle);
  EXPECT_TRUE(rest.bytes == pm.substr(offsets[middle], offsets[n] - offsets[middle]));
  EXPECT_EQ(decode_partial(pm.substr(0, offsets[middle]) + rest.bytes, n, &base_faces),
            positions_at(pm, n));

  // Past the end: refused.
  request.set_from_vsplit(n + 1);
  EXPECT_EQ(stream_pm(service(), request).status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);

  // Up to a face count: the records of that level exactly.
  std::istringstream in(pm);
  const ProgressiveMesh local = read_pm(in);
  const uint64_t max_faces = (job.base_faces() + job.input_faces()) / 2;
  const size_t level = level_for_faces(local, max_faces);
  request.set_from_vsplit(0);
  request.set_max_faces(max_faces);
  const Streamed cut = stream_pm(service(), request);
  ASSERT_TRUE(cut.status.ok()) << status_text(cut.status);
  EXPECT_EQ(cut.records, level);
  EXPECT_EQ(decode_partial(cut.bytes, cut.records, &base_faces), positions_at(pm, level));

  // GetLevel: that level as an OBJ (and a PLY) with at most max_faces faces.
  const Mesh expected = level_of_detail(local, level);
  for (const std::string format : {"obj", "ply"}) {
    SCOPED_TRACE(format);
    grpc::ClientContext context;
    rpc::attach_token(context, service().token());
    parapm::v1::LevelRequest level_request;
    level_request.set_job_id(job.job_id());
    level_request.set_max_faces(max_faces);
    level_request.set_format(format);
    auto reader = service().stub().GetLevel(&context, level_request);
    std::string bytes;
    parapm::v1::Chunk chunk;
    while (reader->Read(&chunk)) {
      EXPECT_EQ(chunk.offset(), bytes.size());
      bytes += chunk.data();
    }
    const grpc::Status status = reader->Finish();
    ASSERT_TRUE(status.ok()) << status_text(status);
    const Mesh got = read_mesh_from_memory(bytes, "level." + format);
    EXPECT_LE(got.face_count(), max_faces);
    EXPECT_EQ(got.face_count(), expected.face_count());
    if (format == "obj") {
      EXPECT_EQ(got.positions, expected.positions);
      EXPECT_EQ(got.faces, expected.faces);
    }
  }
}

// The standard grpc.health.v1 check, called by name through a generic stub (no generated
// health client here): HealthCheckRequest{service: ""} is empty bytes, and the reply
// HealthCheckResponse{status: SERVING} is field 1 = 1, the bytes 08 01.
std::string health_check(const std::string& address, grpc::Status* status) {
  grpc::GenericStub stub(grpc::CreateChannel(address, grpc::InsecureChannelCredentials()));
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + seconds(10));
  grpc::CompletionQueue queue;
  grpc::Slice empty(std::string{});
  grpc::ByteBuffer request(&empty, 1);
  auto call = stub.PrepareUnaryCall(&context, "/grpc.health.v1.Health/Check", request, &queue);
  call->StartCall();
  grpc::ByteBuffer response;
  call->Finish(&response, status, reinterpret_cast<void*>(1));
  void* tag = nullptr;
  bool ok = false;
  queue.Next(&tag, &ok);
  queue.Shutdown();
  while (queue.Next(&tag, &ok)) {
  }
  std::vector<grpc::Slice> slices;
  std::string bytes;
  if (status->ok() && response.Dump(&slices).ok())
    for (const grpc::Slice& s : slices)
      bytes.append(reinterpret_cast<const char*>(s.begin()), s.size());
  return bytes;
}

// "listening on 127.0.0.1:PORT" from a daemon's log.
std::string listening_address(const std::string& log) {
  const std::string key = "listening on ";
  const size_t at = log.find(key);
  if (at == std::string::npos) return "";
  const size_t end = log.find_first_of(" \n", at + key.size());
  return log.substr(at + key.size(), end - at - key.size());
}

TEST_F(ServiceJobs, HealthCheckAndCleanStop) {
  start(1);
  grpc::Status status;
  EXPECT_EQ(health_check(service().address(), &status), std::string("\x08\x01", 2));
  EXPECT_TRUE(status.ok()) << status_text(status);
  const std::string worker_address = listening_address(service().worker("w1")->log());
  ASSERT_NE(worker_address, "") << service().worker("w1")->log();
  EXPECT_EQ(health_check(worker_address, &status), std::string("\x08\x01", 2));
  EXPECT_TRUE(status.ok()) << status_text(status);

  // SIGTERM: both daemons stop cleanly (exit 0) within their grace period.
  for (ChildProcess* process : {service().worker("w1"), &service().coordinator()}) {
    process->signal(SIGTERM);
    const std::optional<int> exit = process->wait(seconds(10));
    ASSERT_TRUE(exit.has_value()) << process->name() << " still running 10 s after SIGTERM";
    EXPECT_TRUE(WIFEXITED(*exit) && WEXITSTATUS(*exit) == 0)
        << process->name() << " ended with wait status " << *exit;
    EXPECT_NE(process->log().find("SIGTERM: stopping"), std::string::npos) << process->log();
  }
}

}  // namespace
}  // namespace parapm::service_test
