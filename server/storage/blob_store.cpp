#include "storage/blob_store.h"

#include <fcntl.h>
#include <spdlog/spdlog.h>
#include <sys/stat.h>
#include <unistd.h>
#include <algorithm>
#include <cerrno>
#include <cstring>
#include <system_error>

#include "storage/ids.h"
#include "util/error.h"

namespace parapm::service {

namespace fs = std::filesystem;

namespace {

// The path goes to the log, not into the message: messages reach clients.
[[noreturn]] void throw_io(const std::string& what, const fs::path& path, int errno_value) {
  spdlog::error("blob store: {} ({}): {}", what, path.string(), std::strerror(errno_value));
  throw Error(ErrorCode::kIo, "blob store: " + what + ": " + std::strerror(errno_value));
}

void make_dir(const fs::path& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw Error(ErrorCode::kIo, "blob store: creating " + dir.string() + ": " + ec.message());
}

// A rename is durable only once the folder holding the new name is on disk too.
void fsync_dir(const fs::path& dir) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) throw_io("opening a folder", dir, errno);
  const int rc = ::fsync(fd);
  const int saved = errno;
  ::close(fd);
  if (rc != 0) throw_io("fsync of a folder", dir, saved);
}

// Temp files are only ever written by a live Writer of this process, so at start-up every
// file in the temp folder is debris from a crash.
void remove_stale_temp_files(const fs::path& temp_dir) {
  std::error_code ec;
  size_t removed = 0;
  for (const auto& entry : fs::directory_iterator(temp_dir, ec)) {
    std::error_code remove_ec;
    if (fs::remove_all(entry.path(), remove_ec) > 0) ++removed;
    if (remove_ec)
      spdlog::warn("blob store: could not remove stale temp file {}: {}", entry.path().string(),
                   remove_ec.message());
  }
  if (ec)
    throw Error(ErrorCode::kIo, "blob store: listing " + temp_dir.string() + ": " + ec.message());
  if (removed > 0)
    spdlog::info("blob store: removed {} stale temp files from {}", removed, temp_dir.string());
}

// Calls visit(path, name) for every file in the shard folders (not the temp folder).
template <class Visit>
void for_each_blob_file(const fs::path& blobs_dir, const fs::path& temp_dir, Visit visit) {
  std::error_code ec;
  for (const auto& shard : fs::directory_iterator(blobs_dir, ec)) {
    if (!shard.is_directory() || shard.path() == temp_dir) continue;
    for (const auto& entry : fs::directory_iterator(shard.path(), ec))
      if (entry.is_regular_file()) visit(entry.path(), entry.path().filename().string());
  }
  if (ec) throw_io("listing the blobs", blobs_dir, ec.value());
}

// The bytes of blob `sha` at `path`, checked against the hash (see BlobStore::read).
std::string read_checked(const fs::path& path, const std::string& sha) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    if (errno == ENOENT) throw Error(ErrorCode::kNotFound, "blob store: no blob " + sha);
    throw_io("opening blob " + sha, path, errno);
  }
  std::string bytes;
  struct stat info {};
  if (::fstat(fd, &info) == 0 && info.st_size > 0) bytes.reserve(static_cast<size_t>(info.st_size));
  char buffer[1 << 16];
  for (;;) {
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n == 0) break;
    if (n < 0) {
      if (errno == EINTR) continue;
      const int saved = errno;
      ::close(fd);
      throw_io("reading blob " + sha, path, saved);
    }
    bytes.append(buffer, static_cast<size_t>(n));
  }
  ::close(fd);
  if (sha256_hex(bytes) != sha) {
    spdlog::critical("blob store: {} is corrupt: its {} bytes no longer hash to its name",
                     path.string(), bytes.size());
    throw Error(ErrorCode::kDataLoss, "stored blob " + sha +
                                          " is corrupt (its bytes no longer match their hash); "
                                          "the operator has been told in the log");
  }
  return bytes;
}

}  // namespace

BlobStore::BlobStore(fs::path data_dir)
    : blobs_dir_(data_dir / "blobs"), temp_dir_(data_dir / "blobs" / "tmp") {
  make_dir(temp_dir_);
  remove_stale_temp_files(temp_dir_);
}

// ---- Writer

BlobStore::Writer::Writer(const BlobStore& store, fs::path temp_path, int fd)
    : store_(&store), temp_path_(std::move(temp_path)), fd_(fd) {}

BlobStore::Writer::Writer(Writer&& other) noexcept
    : store_(other.store_),
      temp_path_(std::move(other.temp_path_)),
      fd_(other.fd_),
      size_(other.size_),
      hash_(std::move(other.hash_)) {
  other.fd_ = -1;
}

BlobStore::Writer& BlobStore::Writer::operator=(Writer&& other) noexcept {
  if (this != &other) {
    discard();
    store_ = other.store_;
    temp_path_ = std::move(other.temp_path_);
    fd_ = other.fd_;
    size_ = other.size_;
    hash_ = std::move(other.hash_);
    other.fd_ = -1;
  }
  return *this;
}

BlobStore::Writer::~Writer() { discard(); }

void BlobStore::Writer::discard() noexcept {
  if (fd_ < 0) return;
  ::close(fd_);
  fd_ = -1;
  ::unlink(temp_path_.c_str());
}

void BlobStore::Writer::write(std::string_view bytes) {
  if (fd_ < 0) throw_internal("blob store: write() on a finished writer");
  hash_.update(bytes);
  while (!bytes.empty()) {
    const ssize_t n = ::write(fd_, bytes.data(), bytes.size());
    if (n < 0) {
      if (errno == EINTR) continue;
      throw_io("writing a new blob", temp_path_, errno);
    }
    bytes.remove_prefix(static_cast<size_t>(n));
    size_ += static_cast<uint64_t>(n);
  }
}

std::string BlobStore::Writer::commit() {
  if (fd_ < 0) throw_internal("blob store: commit() on a finished writer");
  // On any failure below the destructor still removes the temp file.
  if (::fsync(fd_) != 0) throw_io("fsync of a new blob", temp_path_, errno);
  const std::string sha = hash_.hex();
  const fs::path target = store_->path_of(sha);
  make_dir(target.parent_path());
  std::error_code ec;
  if (fs::exists(target, ec)) {
    discard();  // the same bytes are stored already
    // Fresh again, so that garbage collection (which spares young blobs) cannot remove it
    // before the caller's row names it.
    ::utimensat(AT_FDCWD, target.c_str(), nullptr, 0);
    return sha;
  }
  // rename() replaces atomically, so two writers committing the same bytes at once both
  // succeed and leave one complete file.
  if (::rename(temp_path_.c_str(), target.c_str()) != 0)
    throw_io("renaming a new blob to " + sha, target, errno);
  ::close(fd_);
  fd_ = -1;
  fsync_dir(target.parent_path());
  return sha;
}

// ---- BlobStore

BlobStore::Writer BlobStore::begin() {
  const fs::path temp_path = temp_dir_ / new_id("put-");
  const int fd = ::open(temp_path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) throw_io("creating a new blob", temp_path, errno);
  return Writer(*this, temp_path, fd);
}

std::string BlobStore::put(std::string_view bytes) {
  Writer writer = begin();
  writer.write(bytes);
  return writer.commit();
}

bool BlobStore::contains(const std::string& sha) const {
  if (!is_sha256_hex(sha)) return false;
  std::error_code ec;
  return fs::is_regular_file(path_of(sha), ec);
}

fs::path BlobStore::path_of(const std::string& sha) const {
  if (!is_sha256_hex(sha))
    throw_invalid("blob store: '" + sha.substr(0, 80) +
                  "' is not a SHA-256 hash (64 lowercase hex characters)");
  return blobs_dir_ / sha.substr(0, 2) / sha;
}

uint64_t BlobStore::size_of(const std::string& sha) const {
  const fs::path path = path_of(sha);
  std::error_code ec;
  const uint64_t size = fs::file_size(path, ec);
  if (ec == std::errc::no_such_file_or_directory)
    throw Error(ErrorCode::kNotFound, "blob store: no blob " + sha);
  if (ec) {
    spdlog::error("blob store: size of {}: {}", path.string(), ec.message());
    throw Error(ErrorCode::kIo, "blob store: size of blob " + sha + ": " + ec.message());
  }
  return size;
}

std::string BlobStore::read(const std::string& sha) const {
  return read_checked(path_of(sha), sha);
}

BlobStore::VerifyReport BlobStore::verify(const fs::path& data_dir) {
  const fs::path blobs_dir = data_dir / "blobs", temp_dir = blobs_dir / "tmp";
  VerifyReport report;
  std::vector<std::string> names;
  for_each_blob_file(blobs_dir, temp_dir,
                     [&](const fs::path&, const std::string& name) { names.push_back(name); });
  std::sort(names.begin(), names.end());
  for (const std::string& name : names) {
    ++report.blobs;
    try {
      if (!is_sha256_hex(name)) throw_invalid("not a blob name");
      report.bytes += read_checked(blobs_dir / name.substr(0, 2) / name, name).size();
    } catch (const Error&) {
      report.corrupt.push_back(name);  // read() logged why
    }
  }
  return report;
}

BlobStore::Removed BlobStore::remove_unreferenced(const std::set<std::string>& keep,
                                                  std::chrono::seconds min_age) const {
  Removed removed;
  const auto now = fs::file_time_type::clock::now();
  for_each_blob_file(blobs_dir_, temp_dir_, [&](const fs::path& path, const std::string& name) {
    if (keep.contains(name)) return;
    std::error_code ec;
    const auto modified = fs::last_write_time(path, ec);
    if (ec || now - modified < min_age) return;
    const uint64_t size = fs::file_size(path, ec);
    if (ec || !fs::remove(path, ec)) return;
    ++removed.blobs;
    removed.bytes += size;
  });
  return removed;
}

uint64_t BlobStore::stored_bytes() const {
  uint64_t bytes = 0;
  for_each_blob_file(blobs_dir_, temp_dir_, [&](const fs::path& path, const std::string&) {
    std::error_code ec;
    const uint64_t size = fs::file_size(path, ec);
    if (!ec) bytes += size;
  });
  return bytes;
}

}  // namespace parapm::service
