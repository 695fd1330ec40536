// The last upload's parsed and repaired mesh, kept for the job that follows it: most jobs
// start right after their upload (`parapm submit`), and reading and repairing a large mesh a
// second time is most of a second on the coordinator's critical path. One mesh at most,
// held until a job takes it, the next upload replaces it, or `keep` passes (then freed and
// its memory given back, so that an idle coordinator's memory falls back).
#pragma once

#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "mesh/repair.h"

namespace parapm::service {

class UploadHandoff {
 public:
  explicit UploadHandoff(std::chrono::milliseconds keep);
  ~UploadHandoff();
  UploadHandoff(const UploadHandoff&) = delete;
  UploadHandoff& operator=(const UploadHandoff&) = delete;

  // The mesh parsed from the upload whose bytes hash to `sha256`.
  void put(const std::string& sha256, std::shared_ptr<const RepairedMesh> mesh);
  // That mesh, once (null when another upload replaced it, or it expired).
  std::shared_ptr<const RepairedMesh> take(const std::string& sha256);

 private:
  void expire_loop();

  std::chrono::milliseconds keep_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::string sha256_;
  std::shared_ptr<const RepairedMesh> mesh_;
  std::chrono::steady_clock::time_point deadline_;
  bool stopping_ = false;
  std::thread expirer_;  // last: starts once the members above exist
};

}  // namespace parapm::service
