// Which listening addresses count as loopback (a daemon may listen there without a token),
// and how a peer string names its client: decided by the address's value, never its text.
#include <gtest/gtest.h>

#include "call_admission.h"
#include "rpc_security.h"

namespace parapm::rpc {
namespace {

TEST(RpcSecurity, LoopbackIsDecidedByTheAddressNotItsText) {
  for (const char* loopback :
       {"127.0.0.1:50051", "127.1.2.3:0", "[::1]:50051", "localhost:50051", "LOCALHOST:1",
        "ipv4:127.0.0.1:5", "ipv6:[::1]:5", "[::ffff:127.0.0.1]:5"})
    EXPECT_TRUE(is_loopback_address(loopback)) << loopback;
  for (const char* beyond :
       {"127.evil.example:50051", "127.0.0.1.nip.io:50051", "0.0.0.0:50051", "[::]:50051",
        "10.0.0.1:50051", "[2001:db8::1]:50051", "localhost.example:1", "[::1:50051", "128.0.0.1:1",
        "[::ffff:10.0.0.1]:5", ":50051"})
    EXPECT_FALSE(is_loopback_address(beyond)) << beyond;
}

TEST(RpcSecurity, PeerClientIsTheAddressWithoutThePort) {
  EXPECT_EQ(peer_client("ipv4:127.0.0.1:54321"), "127.0.0.1");
  EXPECT_EQ(peer_client("ipv6:[::1]:54321"), "::1");
  EXPECT_EQ(peer_client("unix:/tmp/socket"), "unix");
}

}  // namespace
}  // namespace parapm::rpc
