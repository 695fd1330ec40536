// The coordinator's library of PMs it serves: a PM put as it was written is served from memory
// (no blob read), within a budget that counts the decoded PMs too; one it no longer holds is
// read from its blob again and checked; one entry per PM.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <optional>

#include "io/mesh_io.h"
#include "mesh/repair.h"
#include "pm_library.h"
#include "simplify/simplify.h"
#include "storage/blob_store.h"
#include "util/error.h"

namespace parapm::service {
namespace {

namespace fs = std::filesystem;

// A test mesh's PM written as the coordinator stores one.
std::shared_ptr<LoadedPm> pm_of(const std::string& file, double ratio) {
  SimplifyOptions options;
  options.target_ratio = ratio;
  return written_pm(build_progressive_mesh(
      repair_mesh(read_mesh(std::string(PARAPM_TEST_DATA_DIR) + "/" + file)), options));
}

class PmLibraryTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ =
        fs::temp_directory_path() /
        ("parapm-pm-library-" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
         "-" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    blobs_.emplace(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
  std::optional<BlobStore> blobs_;
};

TEST_F(PmLibraryTest, APutPmIsServedWithoutItsBlob) {
  PmLibrary library;
  const std::shared_ptr<LoadedPm> guitar = pm_of("stratocaster-9k.ply", 0.1);
  const std::string sha = blobs_->put(guitar->bytes);
  fs::remove(blobs_->path_of(sha));  // only the library holds it now
  library.put(sha, guitar);
  EXPECT_EQ(library.get(sha, *blobs_), guitar);
}

TEST_F(PmLibraryTest, TheBudgetCountsTheDecodedPms) {
  const std::shared_ptr<LoadedPm> guitar = pm_of("stratocaster-9k.ply", 0.1);
  const std::shared_ptr<LoadedPm> part = pm_of("cad-featuretype-3k.stl", 0.1);
  // Room for both files, not for both files and their decoded PMs.
  PmLibrary library(guitar->bytes.size() + part->bytes.size());
  const std::string guitar_sha = blobs_->put(guitar->bytes);
  fs::remove(blobs_->path_of(guitar_sha));
  library.put(guitar_sha, guitar);
  library.put(blobs_->put(part->bytes), part);
  try {
    library.get(guitar_sha, *blobs_);
    FAIL() << "the guitar stayed: the budget counted the files only";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kNotFound) << e.what();
  }
}

TEST_F(PmLibraryTest, BeyondTheBudgetAPmIsReadFromItsBlobAgainAndChecked) {
  const std::shared_ptr<LoadedPm> guitar = pm_of("stratocaster-9k.ply", 0.1);
  const std::shared_ptr<LoadedPm> part = pm_of("cad-featuretype-3k.stl", 0.1);
  PmLibrary library(guitar->bytes.size());  // room for the last one used only
  const std::string guitar_sha = blobs_->put(guitar->bytes);
  const std::string part_sha = blobs_->put(part->bytes);
  library.put(guitar_sha, guitar);
  library.put(guitar_sha, guitar);  // kept once
  library.put(part_sha, part);      // the guitar goes

  const std::shared_ptr<const LoadedPm> reloaded = library.get(guitar_sha, *blobs_);
  EXPECT_NE(reloaded, guitar);
  EXPECT_EQ(reloaded->bytes, guitar->bytes);
  EXPECT_EQ(reloaded->splits_begin, guitar->splits_begin);
  EXPECT_EQ(reloaded->split_begin, guitar->split_begin);
  EXPECT_EQ(reloaded->pm.splits.size(), guitar->pm.splits.size());

  // The part went in its turn; its blob changed since: never served.
  std::string changed = part->bytes;
  changed[changed.size() / 2] ^= 1;
  {
    std::ofstream out(blobs_->path_of(part_sha), std::ios::binary | std::ios::trunc);
    out << changed;
  }
  try {
    library.get(part_sha, *blobs_);
    FAIL() << "a changed blob was served";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kDataLoss) << e.what();
  }
}

}  // namespace
}  // namespace parapm::service
