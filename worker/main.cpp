// parapm-worker: placeholder until the service issue lands. It parses its command line so that
// scripts can already call --help, and says plainly that the daemon does not exist yet.
#include <CLI/CLI.hpp>
#include <cstdio>

#include "parapm.grpc.pb.h"

int main(int argc, char** argv) {
  CLI::App app{
      "parapm-worker: not implemented yet (the service issue builds it); use 'parapm simplify' "
      "in-process"};
  CLI11_PARSE(app, argc, argv);
  std::fprintf(stderr,
               "parapm-worker: the gRPC service is not implemented yet; use 'parapm simplify'\n");
  return 2;
}
