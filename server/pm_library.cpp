#include "pm_library.h"

#include <fstream>

#include "pm/pm_file.h"
#include "util/error.h"

namespace parapm::service {
namespace {

std::shared_ptr<const LoadedPm> load(const std::filesystem::path& path) {
  auto loaded = std::make_shared<LoadedPm>();
  loaded->path = path;
  loaded->pm = read_pm_file(path.string());
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(ErrorCode::kIo, "cannot open " + path.string());
  PmReader reader(in, path.string());
  reader.read_base();
  loaded->splits_begin = reader.offset();
  loaded->split_begin.reserve(reader.header().splits + 1);
  PmSplitRecord record;
  loaded->split_begin.push_back(reader.offset());
  while (reader.next_split(record)) loaded->split_begin.push_back(reader.offset());
  loaded->file_size = std::filesystem::file_size(path);
  return loaded;
}

}  // namespace

std::shared_ptr<const LoadedPm> PmLibrary::get(const std::string& sha256,
                                               const std::filesystem::path& path) {
  {
    std::lock_guard lock(mutex_);
    for (auto it = recent_.begin(); it != recent_.end(); ++it)
      if (it->first == sha256) {
        recent_.splice(recent_.begin(), recent_, it);
        return it->second;
      }
  }
  std::shared_ptr<const LoadedPm> loaded = load(path);
  std::lock_guard lock(mutex_);
  recent_.emplace_front(sha256, loaded);
  while (recent_.size() > capacity_) recent_.pop_back();
  return loaded;
}

std::string read_file_range(const std::filesystem::path& path, uint64_t begin, uint64_t end) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(ErrorCode::kIo, "cannot open " + path.string());
  std::string bytes(end - begin, '\0');
  in.seekg(std::streamoff(begin));
  in.read(bytes.data(), std::streamsize(bytes.size()));
  if (!in) throw Error(ErrorCode::kIo, "cannot read " + path.string());
  return bytes;
}

}  // namespace parapm::service
