// parapm view JOB: the address of the job's page in the coordinator's viewer (parapm-coordinator
// --http; parapm up serves it at 127.0.0.1:50052), after checking that the job exists; opened
// in the desktop's browser where there is one.
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>

#include <unistd.h>

#include "commands.h"
#include "service_client.h"

namespace parapm::cli {
namespace {

struct ViewArgs {
  ConnectionArgs connection;
  std::string job_id;
  std::string viewer = std::string("http://") + kDefaultViewer + "/";
  bool open = true;
};

// Characters a URL fragment may hold as they are; others are percent-encoded.
std::string fragment_value(const std::string& text) {
  std::string out;
  for (const unsigned char c : text) {
    if (std::isalnum(c) || c == '-' || c == '_' || c == '.' || c == '~') {
      out += char(c);
    } else {
      char escaped[4];
      std::snprintf(escaped, sizeof escaped, "%%%02X", c);
      out += escaped;
    }
  }
  return out;
}

bool has_desktop() {
  return (std::getenv("DISPLAY") || std::getenv("WAYLAND_DISPLAY")) &&
         std::filesystem::exists("/usr/bin/xdg-open");
}

int run_view(const ViewArgs& args) {
  ServiceClient client(args.connection);
  auto context = client.context();
  parapm::v1::JobRef ref;
  ref.set_job_id(args.job_id);
  parapm::v1::Job job;
  check_status(client.stub().GetJob(context.get(), ref, &job), "get job " + args.job_id,
               client.server());
  std::string url = args.viewer;
  if (url.empty() || url.back() != '/') url += '/';
  url += "#job=" + fragment_value(job.job_id());
  // The token rides in the fragment, which browsers never send to the server.
  if (!client.token().empty()) url += "&token=" + fragment_value(client.token());
  std::printf("%s\n", url.c_str());
  std::fflush(stdout);
  if (args.open && has_desktop()) {
    if (fork() == 0) {
      execl("/usr/bin/xdg-open", "xdg-open", url.c_str(), static_cast<char*>(nullptr));
      _exit(127);
    }
  }
  return 0;
}

}  // namespace

void add_view_command(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<ViewArgs>();
  CLI::App* view = app.add_subcommand(
      "view",
      "print the address of a job's page in the coordinator's viewer (and open it where a "
      "desktop browser is)");
  view->add_option("job", args->job_id, "the job id (parapm jobs lists them)")->required();
  view->add_option("--viewer", args->viewer,
                   "the viewer's address (parapm-coordinator --http; parapm up's by default)")
      ->capture_default_str();
  view->add_flag("!--no-open", args->open, "only print the address");
  add_connection_options(view, args->connection);
  view->callback([args, &exit_code] { exit_code = run_view(*args); });
}

}  // namespace parapm::cli
