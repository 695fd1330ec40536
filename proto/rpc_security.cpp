#include "rpc_security.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <strings.h>

#include <cstdlib>
#include <fstream>
#include <sstream>

#include "util/error.h"

namespace parapm::rpc {
namespace {

std::string read_text_file(const std::string& path, const char* what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(ErrorCode::kNotFound, std::string(what) + " " + path + ": cannot open");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string trimmed(const std::string& s) {
  const auto first = s.find_first_not_of(" \t\r\n");
  if (first == std::string::npos) return "";
  return s.substr(first, s.find_last_not_of(" \t\r\n") - first + 1);
}

}  // namespace

std::string load_token(const std::string& token_file) {
  if (!token_file.empty()) {
    std::string token = trimmed(read_text_file(token_file, "token file"));
    if (token.empty()) throw_invalid("token file " + token_file + " is empty");
    return token;
  }
  const char* env = std::getenv("PARAPM_TOKEN");
  return env ? trimmed(env) : std::string();
}

bool is_loopback_address(const std::string& address) {
  std::string host = address;
  if (host.rfind("ipv4:", 0) == 0 || host.rfind("ipv6:", 0) == 0) host = host.substr(5);
  if (!host.empty() && host[0] == '[') {
    const auto close = host.find(']');
    if (close == std::string::npos) return false;
    host = host.substr(1, close - 1);
  } else {
    host = host.substr(0, host.rfind(':'));
  }
  // Addresses are decided by their value, never by their text: "127.evil.example" is a name.
  in_addr v4{};
  if (::inet_pton(AF_INET, host.c_str(), &v4) == 1) return (ntohl(v4.s_addr) >> 24) == 127;
  in6_addr v6{};
  if (::inet_pton(AF_INET6, host.c_str(), &v6) == 1) {
    if (IN6_IS_ADDR_LOOPBACK(&v6)) return true;
    // ::ffff:127.x.y.z, IPv4-mapped loopback.
    return IN6_IS_ADDR_V4MAPPED(&v6) && v6.s6_addr[12] == 127;
  }
  // The one name that means this machine by definition (RFC 6761); any other may resolve
  // anywhere.
  return strcasecmp(host.c_str(), "localhost") == 0;
}

std::shared_ptr<grpc::ServerCredentials> server_credentials(const TlsFiles& tls) {
  if (tls.cert_file.empty() != tls.key_file.empty())
    throw_invalid("TLS needs both a certificate (--tls-cert) and a key (--tls-key)");
  if (!tls.server_enabled()) return grpc::InsecureServerCredentials();
  grpc::SslServerCredentialsOptions options;
  options.pem_key_cert_pairs.push_back(
      {read_text_file(tls.key_file, "TLS key"), read_text_file(tls.cert_file, "TLS certificate")});
  return grpc::SslServerCredentials(options);
}

std::shared_ptr<grpc::ChannelCredentials> channel_credentials(bool tls, const TlsFiles& files) {
  if (!tls) return grpc::InsecureChannelCredentials();
  grpc::SslCredentialsOptions options;
  if (!files.ca_file.empty()) options.pem_root_certs = read_text_file(files.ca_file, "TLS CA");
  return grpc::SslCredentials(options);
}

std::shared_ptr<grpc::Channel> make_channel(
    const std::string& address, const std::shared_ptr<grpc::ChannelCredentials>& creds) {
  grpc::ChannelArguments args;
  args.SetMaxReceiveMessageSize(kMaxMessageBytes);
  args.SetMaxSendMessageSize(kMaxMessageBytes);
  // A dead peer is noticed by keepalive pings, not only when a write fails.
  args.SetInt(GRPC_ARG_KEEPALIVE_TIME_MS, 10000);
  args.SetInt(GRPC_ARG_KEEPALIVE_TIMEOUT_MS, 5000);
  args.SetInt(GRPC_ARG_KEEPALIVE_PERMIT_WITHOUT_CALLS, 1);
  return grpc::CreateCustomChannel(address, creds, args);
}

grpc::Status TokenCheck::check(const grpc::ServerContext& context) const {
  if (token_.empty()) return grpc::Status::OK;
  const auto& metadata = context.client_metadata();
  const auto it = metadata.find("authorization");
  if (it == metadata.end())
    return {grpc::StatusCode::UNAUTHENTICATED,
            "this server needs a bearer token (--token-file or PARAPM_TOKEN)"};
  const std::string given(it->second.data(), it->second.size());
  const std::string expected = "Bearer " + token_;
  // Constant time in the token's length: the comparison does not reveal a matching prefix.
  unsigned char diff = given.size() == expected.size() ? 0 : 1;
  for (size_t i = 0; i < expected.size(); ++i)
    diff |= static_cast<unsigned char>(expected[i] ^ (i < given.size() ? given[i] : 0));
  if (diff != 0) return {grpc::StatusCode::UNAUTHENTICATED, "the bearer token is wrong"};
  return grpc::Status::OK;
}

void attach_token(grpc::ClientContext& context, const std::string& token) {
  if (!token.empty()) context.AddMetadata("authorization", "Bearer " + token);
}

}  // namespace parapm::rpc
