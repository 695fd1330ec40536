// The content-addressed blob store on a real folder: layout, streamed and whole puts,
// idempotence, temp files of abandoned writers and of a crash, and refused hash names.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "storage/blob_store.h"
#include "storage_test_util.h"
#include "test_support.h"

namespace parapm::service {
namespace {

namespace fs = std::filesystem;
using testing::expect_error;
using testing::TempDir;

const std::string kAbcSha = "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad";

size_t files_in(const fs::path& dir) {
  size_t count = 0;
  for (const auto& entry : fs::directory_iterator(dir)) count += entry.is_regular_file() ? 1 : 0;
  return count;
}

std::string some_bytes(size_t size) {
  std::string bytes;
  for (size_t i = 0; i < size; ++i) bytes.push_back(static_cast<char>((i * 131) ^ (i >> 7)));
  return bytes;
}

TEST(BlobStore, PutStoresUnderItsHashInAShardFolder) {
  TempDir dir;
  BlobStore store(dir.path());
  EXPECT_TRUE(fs::is_directory(dir.path() / "blobs" / "tmp"));
  EXPECT_EQ(store.put("abc"), kAbcSha);
  EXPECT_EQ(store.path_of(kAbcSha), dir.path() / "blobs" / "ba" / kAbcSha);
  EXPECT_TRUE(store.contains(kAbcSha));
  EXPECT_EQ(store.size_of(kAbcSha), 3u);
  EXPECT_EQ(store.read(kAbcSha), "abc");
  EXPECT_EQ(files_in(store.temp_dir()), 0u);
}

TEST(BlobStore, EmptyBlobIsStoredLikeAnyOther) {
  TempDir dir;
  BlobStore store(dir.path());
  const std::string sha = store.put("");
  EXPECT_EQ(sha, "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(store.size_of(sha), 0u);
  EXPECT_EQ(store.read(sha), "");
}

TEST(BlobStore, StreamedWriterEqualsPut) {
  TempDir streamed_dir, whole_dir;
  BlobStore streamed(streamed_dir.path()), whole(whole_dir.path());
  const std::string bytes = some_bytes(300000);
  BlobStore::Writer writer = streamed.begin();
  for (size_t at = 0; at < bytes.size(); at += 7777)
    writer.write(std::string_view(bytes).substr(at, 7777));
  EXPECT_EQ(writer.size(), bytes.size());
  const std::string sha = writer.commit();
  EXPECT_EQ(sha, whole.put(bytes));
  EXPECT_EQ(sha, sha256_hex(bytes));
  EXPECT_EQ(streamed.read(sha), bytes);
  EXPECT_EQ(files_in(streamed.temp_dir()), 0u);
}

TEST(BlobStore, PutIsIdempotent) {
  TempDir dir;
  BlobStore store(dir.path());
  const std::string bytes = some_bytes(5000);
  const std::string first = store.put(bytes);
  EXPECT_EQ(store.put(bytes), first);
  EXPECT_EQ(files_in(store.path_of(first).parent_path()), 1u);
  EXPECT_EQ(files_in(store.temp_dir()), 0u);
  EXPECT_EQ(store.read(first), bytes);
}

TEST(BlobStore, SameBytesFromManyThreadsGiveOneFile) {
  TempDir dir;
  BlobStore store(dir.path());
  const std::string bytes = some_bytes(100000);
  std::vector<std::string> hashes(8);
  std::vector<std::thread> threads;
  for (size_t t = 0; t < hashes.size(); ++t)
    threads.emplace_back([&, t] { hashes[t] = store.put(bytes); });
  for (std::thread& thread : threads) thread.join();
  for (const std::string& sha : hashes) EXPECT_EQ(sha, sha256_hex(bytes));
  EXPECT_EQ(files_in(store.path_of(hashes[0]).parent_path()), 1u);
  EXPECT_EQ(files_in(store.temp_dir()), 0u);
  EXPECT_EQ(store.read(hashes[0]), bytes);
}

TEST(BlobStore, AbandonedWriterLeavesNoTempFile) {
  TempDir dir;
  BlobStore store(dir.path());
  {
    BlobStore::Writer writer = store.begin();
    writer.write("abc");
    EXPECT_EQ(files_in(store.temp_dir()), 1u);
  }
  EXPECT_EQ(files_in(store.temp_dir()), 0u);
  EXPECT_FALSE(store.contains(kAbcSha));
}

TEST(BlobStore, MovedWriterKeepsItsBytes) {
  TempDir dir;
  BlobStore store(dir.path());
  BlobStore::Writer first = store.begin();
  first.write("a");
  BlobStore::Writer second = std::move(first);
  second.write("bc");
  EXPECT_EQ(second.commit(), kAbcSha);
  EXPECT_EQ(files_in(store.temp_dir()), 0u);
}

TEST(BlobStore, FinishedWriterRefusesMoreWork) {
  TempDir dir;
  BlobStore store(dir.path());
  BlobStore::Writer writer = store.begin();
  writer.write("abc");
  writer.commit();
  expect_error([&] { writer.write("more"); }, ErrorCode::kInternal, {"finished writer"});
  expect_error([&] { writer.commit(); }, ErrorCode::kInternal, {"finished writer"});
}

TEST(BlobStore, ReopeningRemovesStaleTempFilesAndKeepsBlobs) {
  TempDir dir;
  std::string sha;
  {
    BlobStore store(dir.path());
    sha = store.put("kept");
  }
  // What a crash mid-upload leaves behind.
  testing::write_file(dir.path() / "blobs" / "tmp" / "put-0123456789abcdef", "half an upload");
  BlobStore reopened(dir.path());
  EXPECT_EQ(files_in(reopened.temp_dir()), 0u);
  EXPECT_EQ(reopened.read(sha), "kept");
}

TEST(BlobStore, MalformedHashesAreRefused) {
  TempDir dir;
  BlobStore store(dir.path());
  store.put("abc");
  std::string upper = kAbcSha;
  for (char& c : upper) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  const std::string traversal = "../" + kAbcSha.substr(3);  // 64 characters, but a path
  for (const std::string& bad : {std::string("../x"), upper, kAbcSha.substr(0, 63), kAbcSha + "0",
                                 traversal, std::string("")}) {
    SCOPED_TRACE(bad);
    EXPECT_FALSE(store.contains(bad));
    expect_error([&] { store.path_of(bad); }, ErrorCode::kInvalidInput, {"not a SHA-256 hash"});
    expect_error([&] { store.read(bad); }, ErrorCode::kInvalidInput, {"not a SHA-256 hash"});
    expect_error([&] { store.size_of(bad); }, ErrorCode::kInvalidInput, {"not a SHA-256 hash"});
  }
}

TEST(BlobStore, MissingBlobIsNotFound) {
  TempDir dir;
  BlobStore store(dir.path());
  EXPECT_FALSE(store.contains(kAbcSha));
  expect_error([&] { store.read(kAbcSha); }, ErrorCode::kNotFound, {"no blob", kAbcSha});
  expect_error([&] { store.size_of(kAbcSha); }, ErrorCode::kNotFound, {"no blob", kAbcSha});
}

// A flipped byte or a cut file is DATA_LOSS naming the blob, not where it lies; verify()
// finds exactly the changed blobs, and leaves the store as it was.
TEST(BlobStore, ChangedBytesAreDataLossAndVerifyFindsThem) {
  TempDir dir;
  BlobStore store(dir.path());
  const std::string flipped = store.put(some_bytes(5000));
  const std::string cut = store.put(some_bytes(7000));
  const std::string intact = store.put(some_bytes(9000));
  std::string bytes = some_bytes(5000);
  bytes[1234] ^= 0x10;
  testing::write_file(store.path_of(flipped), bytes);
  testing::write_file(store.path_of(cut), some_bytes(6999));
  for (const std::string& sha : {flipped, cut}) {
    try {
      store.read(sha);
      ADD_FAILURE() << "read of a changed blob succeeded";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::kDataLoss);
      EXPECT_NE(std::string(e.what()).find(sha), std::string::npos) << e.what();
      EXPECT_EQ(std::string(e.what()).find(dir.path().string()), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(store.read(intact), some_bytes(9000));
  const BlobStore::VerifyReport report = BlobStore::verify(dir.path());
  EXPECT_EQ(report.blobs, 3u);
  std::vector<std::string> expected = {flipped, cut};
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(report.corrupt, expected);
  EXPECT_TRUE(store.contains(flipped));  // verify reports; it removes nothing
}

TEST(BlobStore, StoresACommittedMeshFileUnderItsSha256sum) {
  TempDir dir;
  BlobStore store(dir.path());
  const std::string bytes = testing::read_file(testing::test_data("cad-featuretype-3k.stl"));
  // `sha256sum tests/data/cad-featuretype-3k.stl`, computed once.
  const std::string expected = "c9946c4bb8034cd43522526a2f325200e2d2322a0c7258f848a81f00e418dab3";
  EXPECT_EQ(store.put(bytes), expected);
  EXPECT_EQ(store.size_of(expected), bytes.size());
  EXPECT_EQ(testing::read_file(store.path_of(expected)), bytes);
}

}  // namespace
}  // namespace parapm::service
