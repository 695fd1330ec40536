// --server, --token-file, --tls and --tls-ca of the service commands.
#include "service_client.h"

namespace parapm::cli {

void add_connection_options(CLI::App* command, ConnectionArgs& args) {
  command->add_option("--server", args.server,
                      std::string("coordinator address host:port (default: PARAPM_SERVER, else ") +
                          kDefaultServer + ", where 'parapm up' listens)");
  command->add_option("--token-file", args.token_file,
                      "file holding the bearer token (default: PARAPM_TOKEN)");
  command->add_flag("--tls", args.tls, "connect over TLS");
  command->add_option("--tls-ca", args.tls_ca,
                      "PEM roots that sign the server's certificate (default: the system's)");
}

}  // namespace parapm::cli
