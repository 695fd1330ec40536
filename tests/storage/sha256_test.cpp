// SHA-256 against published vectors (FIPS 180-2 examples) and sha256sum, whole and streamed.
#include <gtest/gtest.h>

#include <string>

#include "storage/sha256.h"
#include "storage_test_util.h"
#include "test_support.h"

namespace parapm::service {
namespace {

TEST(Sha256, KnownVectors) {
  EXPECT_EQ(sha256_hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(sha256_hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(sha256_hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
}

TEST(Sha256, StreamedInPiecesEqualsWhole) {
  std::string bytes;
  for (int i = 0; i < 100000; ++i) bytes.push_back(static_cast<char>(i * 31 + 7));
  Sha256 hash;
  for (size_t at = 0; at < bytes.size(); at += 4099)
    hash.update(std::string_view(bytes).substr(at, 4099));
  EXPECT_EQ(hash.hex(), sha256_hex(bytes));
  EXPECT_EQ(hash.hex(), sha256_hex(bytes)) << "hex() twice returns the same value";
}

TEST(Sha256, UpdateAfterFinishIsABug) {
  Sha256 hash;
  hash.hex();
  testing::expect_error([&] { hash.update("x"); }, ErrorCode::kInternal, {"after hex()"});
}

TEST(Sha256, CommittedMeshMatchesSha256sum) {
  // `sha256sum tests/data/cad-featuretype-3k.stl`, computed once.
  const std::string bytes = testing::read_file(testing::test_data("cad-featuretype-3k.stl"));
  ASSERT_EQ(bytes.size(), 173884u);
  EXPECT_EQ(sha256_hex(bytes), "c9946c4bb8034cd43522526a2f325200e2d2322a0c7258f848a81f00e418dab3");
}

TEST(Sha256, RecognisesOnlyLowercaseHexOfLength64) {
  const std::string good = sha256_hex("abc");
  EXPECT_TRUE(is_sha256_hex(good));
  std::string upper = good;
  upper[0] = 'B';
  EXPECT_FALSE(is_sha256_hex(upper));
  EXPECT_FALSE(is_sha256_hex(good.substr(1)));
  EXPECT_FALSE(is_sha256_hex(good + "0"));
  EXPECT_FALSE(is_sha256_hex("../x"));
  EXPECT_FALSE(is_sha256_hex(""));
}

}  // namespace
}  // namespace parapm::service
