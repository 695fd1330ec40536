// Bytes in: whole files, gzip (concatenated members, corrupt and truncated data, bombs), the
// format chosen by name or by content, and missing or empty files.
#include <gtest/gtest.h>

#include <fstream>

#include "io/byte_input.h"
#include "io/byte_output.h"
#include "io_test_util.h"

namespace parapm {
namespace {

using testing::expect_error;
using testing::read_text;
using testing::TempDir;

const std::string kObj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

void write_raw(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

TEST(Gzip, RoundTripAndConcatenatedMembers) {
  const std::string a = "first member\n", b = std::string(100000, 'x');
  EXPECT_EQ(io::gunzip(io::gzip_compress(a), "a.gz", 1 << 20), a);
  const std::string two = io::gzip_compress(a) + io::gzip_compress(b);
  EXPECT_EQ(io::gunzip(two, "two.gz", 1 << 20), a + b);
  EXPECT_EQ(io::gunzip(io::gzip_compress(""), "empty.gz", 10), "");
}

// The trailer's size sizes the one-call inflation's buffer: a size that lies is caught (by
// zlib's stream, which then inflates it: the trailer's check fails), never trusted.
TEST(Gzip, ATrailerThatLiesAboutTheSizeIsInvalidInput) {
  const std::string data(300000, 'q');
  const std::string gz = io::gzip_compress(data);
  ASSERT_EQ(io::gunzip(gz, "right.gz", 1 << 20), data);
  for (const uint32_t lie : {uint32_t(data.size() - 1), uint32_t(data.size() + 1), uint32_t(0)}) {
    std::string told = gz;
    for (int k = 0; k < 4; ++k) told[told.size() - 4 + k] = char(lie >> (8 * k));
    expect_error([&] { io::gunzip(told, "lies.gz", 1 << 20); }, ErrorCode::kInvalidInput,
                 {"lies.gz", "corrupt"});
  }
}

TEST(Gzip, MeshSplitOverTwoMembersReads) {
  const std::string gz = io::gzip_compress(kObj.substr(0, 20)) + io::gzip_compress(kObj.substr(20));
  ReadReport report;
  const Mesh mesh = read_text(gz, "split.obj.gz", &report);
  EXPECT_TRUE(report.gzip);
  EXPECT_EQ(report.input_bytes, kObj.size());
  EXPECT_EQ(mesh.face_count(), 1u);
}

TEST(Gzip, DetectedByMagicWhateverTheName) {
  ReadReport report;
  const Mesh mesh = read_text(io::gzip_compress(kObj), "named-plainly.obj", &report);
  EXPECT_TRUE(report.gzip);
  EXPECT_EQ(mesh.face_count(), 1u);
}

TEST(Gzip, TruncatedCorruptAndTrailingGarbageAreInvalidInput) {
  const std::string gz = io::gzip_compress(std::string(5000, 'v'));
  expect_error([&] { io::gunzip(gz.substr(0, gz.size() / 2), "cut.gz", 1 << 20); },
               ErrorCode::kInvalidInput, {"cut.gz", "truncated"});
  std::string corrupt = gz;
  for (size_t i = 12; i < corrupt.size() - 8; ++i) corrupt[i] = char(corrupt[i] ^ 0x5a);
  expect_error([&] { io::gunzip(corrupt, "bad.gz", 1 << 20); }, ErrorCode::kInvalidInput,
               {"bad.gz", "corrupt"});
  expect_error([&] { io::gunzip(gz + "garbage", "tail.gz", 1 << 20); }, ErrorCode::kInvalidInput,
               {"tail.gz", "not another gzip member"});
  expect_error([&] { read_text(std::string("\x1f\x8b", 2), "magic-only.ply"); },
               ErrorCode::kInvalidInput, {"magic-only.ply"});
}

// 64 MiB of zeros compress to ~64 KiB: inflating stops at the limit, never allocating more.
TEST(Gzip, BombStopsAtTheLimit) {
  const std::string bomb = io::gzip_compress(std::string(64u << 20, '\0'));
  ASSERT_LT(bomb.size(), 1u << 20);
  expect_error([&] { io::gunzip(bomb, "bomb.gz", 1 << 20); }, ErrorCode::kResourceExhausted,
               {"bomb.gz", "limit of 1048576 bytes"});
  // A bomb whose start looks like a mesh stops at the reader's limit.
  const std::string ply_bomb = io::gzip_compress("ply\n" + std::string(64u << 20, ' '));
  ReadLimits limits;
  limits.max_bytes = 4096;
  expect_error([&] { read_text(ply_bomb, "bomb.ply.gz", nullptr, limits); },
               ErrorCode::kResourceExhausted, {"bomb.ply.gz", "limit of 4096"});
  // Exactly at the limit is fine.
  EXPECT_EQ(io::gunzip(io::gzip_compress(std::string(4096, 'a')), "edge.gz", 4096).size(), 4096u);
}

// A bomb that is no mesh stops after its first 64 KiB, far below the limit, with the reader's
// own message: what it costs does not depend on how large it would inflate.
TEST(Gzip, BombThatIsNoMeshStopsAfterItsStart) {
  const std::string zeros = io::gzip_compress(std::string(64u << 20, '\0'));
  uint64_t seen = 0;
  expect_error(
      [&] {
        io::gunzip(zeros, "zeros.gz", uint64_t(8) << 30, [&](std::string_view start) {
          seen = start.size();
          throw Error(ErrorCode::kInvalidInput, "zeros.gz: not a mesh");
        });
      },
      ErrorCode::kInvalidInput, {"not a mesh"});
  EXPECT_EQ(seen, io::kStartCheckBytes);
  for (const char* name : {"zeros.ply.gz", "zeros.obj.gz", "zeros.off.gz", "zeros.stl.gz"})
    expect_error([&] { read_text(zeros, name); }, ErrorCode::kInvalidInput, {name, "not a"});
  expect_error([&] { read_text(zeros, "zeros.gz"); }, ErrorCode::kInvalidInput,
               {"zeros.gz", "neither the name nor the content tells the format"});
  // A short valid file is checked once, whole, and read.
  EXPECT_EQ(read_text(io::gzip_compress(kObj), "small.obj.gz").face_count(),
            read_text(kObj, "small.obj").face_count());
}

TEST(Files, PlainInputLargerThanTheLimitIsRefused) {
  ReadLimits limits;
  limits.max_bytes = 10;
  expect_error([&] { read_text(kObj, "big.obj", nullptr, limits); }, ErrorCode::kResourceExhausted,
               {"big.obj", "limit of 10"});
  TempDir dir;
  write_raw(dir.file("big.obj"), kObj);
  expect_error([&] { read_mesh(dir.file("big.obj"), nullptr, limits); },
               ErrorCode::kResourceExhausted, {"big.obj", "limit of 10"});
}

TEST(Files, MissingEmptyAndDirectory) {
  TempDir dir;
  expect_error([&] { read_mesh(dir.file("nothing.ply")); }, ErrorCode::kNotFound, {"nothing.ply"});
  write_raw(dir.file("empty.ply"), "");
  expect_error([&] { read_mesh(dir.file("empty.ply")); }, ErrorCode::kInvalidInput,
               {"empty.ply", "empty"});
  expect_error([&] { read_mesh(dir.file("")); }, ErrorCode::kIo, {"directory"});
  expect_error([&] { read_text(io::gzip_compress(""), "empty.obj.gz"); }, ErrorCode::kInvalidInput,
               {"empty.obj.gz", "decompresses to nothing"});
}

TEST(Format, FromTheNameIgnoringGz) {
  EXPECT_EQ(format_from_name("a/b/mesh.OBJ"), MeshFormat::kObj);
  EXPECT_EQ(format_from_name("mesh.ply.gz"), MeshFormat::kPly);
  EXPECT_EQ(format_from_name("mesh.off"), MeshFormat::kOff);
  EXPECT_EQ(format_from_name("x.y/mesh.Stl.GZ"), MeshFormat::kStl);
  EXPECT_EQ(format_from_name("mesh.gz"), MeshFormat::kUnknown);
  EXPECT_EQ(format_from_name("x.ply/mesh"), MeshFormat::kUnknown);
  EXPECT_EQ(format_from_name("mesh.txt"), MeshFormat::kUnknown);
  EXPECT_STREQ(format_name(MeshFormat::kPly), "ply");
}

TEST(Format, FromTheContentWhenTheNameSaysNothing) {
  ReadReport report;
  read_text(kObj, "upload", &report);
  EXPECT_EQ(report.format, MeshFormat::kObj);
  read_text("# comment\n" + kObj, "upload.bin", &report);
  EXPECT_EQ(report.format, MeshFormat::kObj);
  read_text(
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
      "property float z\nend_header\n0 0 0\n",
      "upload", &report);
  EXPECT_EQ(report.format, MeshFormat::kPly);
  read_text("# made by hand\nCOFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", "upload", &report);
  EXPECT_EQ(report.format, MeshFormat::kOff);
  read_text(
      "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
      "vertex 0 1 0\nendloop\nendfacet\nendsolid s\n",
      "upload", &report);
  EXPECT_EQ(report.format, MeshFormat::kStl);
  std::string binary_stl(80, '\0');
  binary_stl += std::string("\x01\0\0\0", 4) + std::string(50, '\0');
  read_text(io::gzip_compress(binary_stl), "upload.gz", &report);
  EXPECT_EQ(report.format, MeshFormat::kStl);
  EXPECT_EQ(report.encoding, "binary");
}

TEST(Format, UnknownContentIsAnError) {
  expect_error([] { read_text("just some words\n", "upload"); }, ErrorCode::kInvalidInput,
               {"upload", "tells the format"});
  expect_error([] { read_text(std::string("\x00\x01\x02\x03", 4), "upload"); },
               ErrorCode::kInvalidInput, {"upload"});
}

}  // namespace
}  // namespace parapm
