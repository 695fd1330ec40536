#include "upload_handoff.h"

#include <spdlog/spdlog.h>

#include "util/memory.h"

namespace parapm::service {

UploadHandoff::UploadHandoff(std::chrono::milliseconds keep)
    : keep_(keep), expirer_([this] { expire_loop(); }) {}

UploadHandoff::~UploadHandoff() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
  expirer_.join();
}

void UploadHandoff::put(const std::string& sha256, std::shared_ptr<const RepairedMesh> mesh) {
  std::shared_ptr<const RepairedMesh> replaced;
  {
    std::lock_guard lock(mutex_);
    replaced = std::move(mesh_);
    sha256_ = sha256;
    mesh_ = std::move(mesh);
    deadline_ = std::chrono::steady_clock::now() + keep_;
  }
  changed_.notify_all();
}

std::shared_ptr<const RepairedMesh> UploadHandoff::take(const std::string& sha256) {
  std::lock_guard lock(mutex_);
  if (!mesh_ || sha256_ != sha256) return nullptr;
  sha256_.clear();
  return std::move(mesh_);
}

void UploadHandoff::expire_loop() {
  std::unique_lock lock(mutex_);
  while (!stopping_) {
    if (!mesh_) {
      changed_.wait(lock);
      continue;
    }
    if (changed_.wait_until(lock, deadline_) == std::cv_status::no_timeout) continue;
    if (!mesh_ || std::chrono::steady_clock::now() < deadline_) continue;
    std::shared_ptr<const RepairedMesh> expired = std::move(mesh_);
    sha256_.clear();
    lock.unlock();
    spdlog::debug("upload hand-off: the parsed mesh of an upload no job took in time, freed");
    expired.reset();
    release_free_memory();
    lock.lock();
  }
}

}  // namespace parapm::service
