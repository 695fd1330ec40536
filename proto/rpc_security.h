// The security baseline shared by the daemons and the client: a bearer token on every RPC
// (required when a daemon listens beyond loopback), TLS from certificate and key files, and
// channels with the message limits subset jobs need.
#pragma once

#include <memory>
#include <string>

#include <grpcpp/grpcpp.h>

namespace parapm::rpc {

// Where the token comes from: the file when given (surrounding whitespace dropped), else the
// environment variable PARAPM_TOKEN, else none (""). Throws Error(kNotFound / kInvalidInput)
// for a missing or empty file.
std::string load_token(const std::string& token_file);

// True for "host:port" addresses whose host is an IPv4 address in 127.0.0.0/8, ::1 (also
// IPv4-mapped loopback), or the name "localhost": nothing beyond this machine can connect
// there. Any other name is not loopback, whatever its text ("127.x.example" is a name).
bool is_loopback_address(const std::string& address);

struct TlsFiles {
  std::string cert_file;  // PEM; server: its certificate chain
  std::string key_file;   // PEM; server: its private key
  std::string ca_file;    // PEM; client: the roots that sign the server's certificate
  bool server_enabled() const { return !cert_file.empty(); }
};

// Insecure without a certificate; TLS otherwise. Throws Error when a file cannot be read or
// only one of certificate and key is given.
std::shared_ptr<grpc::ServerCredentials> server_credentials(const TlsFiles& tls);
// `tls`: verify the server against ca_file (or the system roots when empty).
std::shared_ptr<grpc::ChannelCredentials> channel_credentials(bool tls, const TlsFiles& files);

// The largest message either side accepts: a subset job travels in one message (1 GiB:
// subsets of meshes up to a few tens of millions of faces at p >= 2).
constexpr int kMaxMessageBytes = 1 << 30;

std::shared_ptr<grpc::Channel> make_channel(const std::string& address,
                                            const std::shared_ptr<grpc::ChannelCredentials>& creds);

// Server side: checks the "authorization: Bearer <token>" metadata of a call (constant-time
// compare). An empty expected token accepts every call.
class TokenCheck {
 public:
  explicit TokenCheck(std::string token) : token_(std::move(token)) {}
  grpc::Status check(const grpc::ServerContext& context) const;
  bool required() const { return !token_.empty(); }

 private:
  std::string token_;
};

// Client side: adds the token's metadata (nothing for an empty token).
void attach_token(grpc::ClientContext& context, const std::string& token);

}  // namespace parapm::rpc
