#include "pm_library.h"

#include <istream>
#include <sstream>

#include <spdlog/spdlog.h>

#include "pm/pm_file.h"
#include "util/error.h"
#include "util/view_buffer.h"

namespace parapm::service {
namespace {

std::shared_ptr<const LoadedPm> load(const std::string& sha256, const BlobStore& blobs) {
  auto loaded = std::make_shared<LoadedPm>();
  loaded->bytes = blobs.read(sha256);  // kDataLoss when the bytes changed
  const std::string name = "stored PM " + sha256;
  try {
    ViewBuffer buffer(loaded->bytes);
    std::istream in(&buffer);
    loaded->pm = read_pm(in, name);
    in.clear();
    in.seekg(0);
    PmReader reader(in, name);
    reader.read_base();
    loaded->splits_begin = reader.offset();
    loaded->split_begin.reserve(reader.header().splits + 1);
    PmSplitRecord record;
    loaded->split_begin.push_back(reader.offset());
    while (reader.next_split(record)) loaded->split_begin.push_back(reader.offset());
  } catch (const Error& e) {
    // Its hash matched, so these bytes were stored so: a PM the coordinator itself wrote wrong.
    spdlog::critical("{} does not decode: {}", name, e.what());
    throw Error(ErrorCode::kDataLoss, name + " does not decode: " + e.what());
  }
  return loaded;
}

// What a kept PM holds in memory: its file, its decoded arrays and its offsets.
uint64_t memory_of(const LoadedPm& loaded) {
  auto of = [](const auto& v) { return uint64_t(v.capacity()) * sizeof(v[0]); };
  const ProgressiveMesh& pm = loaded.pm;
  const Mesh& base = pm.base;
  return loaded.bytes.capacity() + of(loaded.split_begin) + of(base.positions) + of(base.faces) +
         of(base.wedge_vertex) + of(base.wedge_values) + of(base.face_wedges) + of(pm.splits) +
         of(pm.new_wedge_values) + of(pm.wedge_changes) + of(pm.wedge_change_values) +
         of(pm.vertex_copies) + of(pm.input_vertex_order) + of(pm.input_face_order);
}

}  // namespace

std::shared_ptr<LoadedPm> written_pm(ProgressiveMesh pm) {
  ChunkedLoops one_thread;
  return written_pm(std::move(pm), one_thread);
}

std::shared_ptr<LoadedPm> written_pm(ProgressiveMesh pm, ChunkedLoops& loops) {
  auto written = std::make_shared<LoadedPm>();
  std::ostringstream bytes;
  write_pm(pm, bytes, loops, &written->split_begin);
  written->bytes = std::move(bytes).str();
  written->splits_begin = written->split_begin.front();
  written->pm = std::move(pm);
  return written;
}

std::shared_ptr<const LoadedPm> PmLibrary::get(const std::string& sha256, const BlobStore& blobs) {
  {
    std::lock_guard lock(mutex_);
    for (auto it = recent_.begin(); it != recent_.end(); ++it)
      if (it->first == sha256) {
        recent_.splice(recent_.begin(), recent_, it);
        return it->second;
      }
  }
  std::shared_ptr<const LoadedPm> loaded = load(sha256, blobs);
  std::lock_guard lock(mutex_);
  keep(sha256, loaded);
  return loaded;
}

void PmLibrary::put(const std::string& sha256, std::shared_ptr<const LoadedPm> pm) {
  std::lock_guard lock(mutex_);
  keep(sha256, std::move(pm));
}

// Newest first, one entry per hash (two loads of one PM at once keep one).
void PmLibrary::keep(const std::string& sha256, std::shared_ptr<const LoadedPm> pm) {
  std::erase_if(recent_, [&](const auto& entry) { return entry.first == sha256; });
  recent_.emplace_front(sha256, std::move(pm));
  uint64_t kept = 0;
  for (auto it = recent_.begin(); it != recent_.end();) {
    kept += memory_of(*it->second);
    if (it != recent_.begin() && kept > budget_bytes_)
      it = recent_.erase(it);
    else
      ++it;
  }
}

}  // namespace parapm::service
