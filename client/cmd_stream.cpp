// parapm stream JOB -o DIR: receives a finished job's PM as a viewer would (StreamPM: header
// and base mesh, then vsplit batches) and writes levels as the splits arrive: the base mesh,
// then a level each time the face count has doubled, then the last level.
#include <filesystem>
#include <istream>
#include <optional>
#include <streambuf>

#include <spdlog/spdlog.h>

#include "cli_common.h"
#include "commands.h"
#include "io/mesh_io.h"
#include "pm/levels.h"
#include "pm/pm_file.h"
#include "service_client.h"
#include "util/error.h"

namespace parapm::cli {
namespace {

struct StreamArgs {
  ConnectionArgs connection;
  std::string job_id;
  std::string output_dir;
  uint64_t faces = 0;
  std::optional<double> error;  // unset: to --faces, or the whole PM
  uint32_t batch = 0;
  bool json = false;
};

// The stream's bytes as an istream, pulled message by message, so that PmReader decodes each
// split as soon as its batch has arrived.
class StreamBuffer : public std::streambuf {
 public:
  explicit StreamBuffer(grpc::ClientReader<parapm::v1::PmStreamMessage>& reader)
      : reader_(reader) {}
  uint64_t messages() const { return messages_; }

 protected:
  int_type underflow() override {
    parapm::v1::PmStreamMessage message;
    do {
      if (!reader_.Read(&message)) return traits_type::eof();
      ++messages_;
      current_ = message.has_header_and_base() ? message.header_and_base() : message.vsplit_batch();
    } while (current_.empty());
    setg(current_.data(), current_.data(), current_.data() + current_.size());
    return traits_type::to_int_type(current_[0]);
  }

 private:
  grpc::ClientReader<parapm::v1::PmStreamMessage>& reader_;
  std::string current_;
  uint64_t messages_ = 0;
};

int run_stream(const StreamArgs& args) {
  ServiceClient client(args.connection);
  std::filesystem::create_directories(args.output_dir);
  parapm::v1::StreamRequest request;
  request.set_job_id(args.job_id);
  if (args.error)
    request.set_max_error(*args.error);
  else if (args.faces > 0)
    request.set_max_faces(args.faces);
  request.set_batch_vsplits(args.batch);
  auto context = client.context(0);
  auto reader = client.stub().StreamPM(context.get(), request);
  StreamBuffer buffer(*reader);
  std::istream in(&buffer);
  nlohmann::json written = nlohmann::json::array();
  uint64_t splits = 0;
  try {
    PmReader pm_reader(in, "stream of " + args.job_id, PmReader::Input::kPartialStream);
    ProgressiveMesh pm;
    pm.base = pm_reader.read_base();
    size_t next_write = pm.base.face_count() * 2;
    auto write_level = [&](const char* reason) {
      const Mesh mesh = level_of_detail(pm, pm.splits.size());
      const std::filesystem::path path = std::filesystem::path(args.output_dir) /
                                         ("level-" + std::to_string(mesh.face_count()) + ".obj");
      write_mesh(mesh, path.string());
      spdlog::info("{} vsplits: wrote {} ({} faces, {})", pm.splits.size(), path.string(),
                   mesh.face_count(), reason);
      written.push_back(
          {{"path", path.string()}, {"vsplits", pm.splits.size()}, {"faces", mesh.face_count()}});
    };
    write_level("base mesh");
    PmSplitRecord record;
    size_t faces = pm.base.face_count();
    // The stream ends where the request's bound cut it (or at the last split).
    while (!pm_reader.at_end() && pm_reader.next_split(record)) {
      faces += size_t(record.split.new_faces());
      append_split(pm, record);
      if (faces >= next_write) {
        write_level("doubled");
        next_write = faces * 2;
      }
    }
    splits = pm.splits.size();
    if (written.back()["vsplits"] != splits) write_level("last");
  } catch (const Error&) {
    // A broken call shows as a truncated stream: its status says why.
    const grpc::Status status = reader->Finish();
    check_status(status, "stream " + args.job_id, client.server());
    throw;
  }
  check_status(reader->Finish(), "stream " + args.job_id, client.server());
  if (args.json)
    print_json({{"job_id", args.job_id}, {"vsplits", splits}, {"levels", written}});
  else
    std::printf("received %llu vsplits in %llu messages; wrote %zu levels to %s\n",
                (unsigned long long)splits, (unsigned long long)buffer.messages(), written.size(),
                args.output_dir.c_str());
  return 0;
}

}  // namespace

void add_stream_command(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<StreamArgs>();
  CLI::App* s = app.add_subcommand(
      "stream",
      "receive a finished job's PM as a viewer does (base mesh, then vsplit batches) "
      "and write levels to DIR as the splits arrive (each time the faces double)");
  s->add_option("job", args->job_id, "job id")->required();
  s->add_option("-o,--output", args->output_dir, "folder for the levels (OBJ)")->required();
  auto* faces = s->add_option("--faces", args->faces, "stop at this many faces");
  s->add_option("--error", args->error, "stop at this geometric error")
      ->check(CLI::NonNegativeNumber)
      ->excludes(faces);
  s->add_option("--batch", args->batch, "vsplits per message (default 4096)");
  s->add_flag("--json", args->json, "print the levels written as one JSON object");
  add_connection_options(s, args->connection);
  s->callback([args, &exit_code] { exit_code = run_stream(*args); });
}

}  // namespace parapm::cli
