#include "stream_admission.h"

#include <algorithm>

#include <spdlog/spdlog.h>

namespace parapm::rpc {
namespace {

using Clock = std::chrono::steady_clock;

// How often the watchdog looks: a small part of the idle limit.
std::chrono::milliseconds scan_interval(const StreamLimits& limits) {
  return std::clamp(limits.idle / 4, std::chrono::milliseconds(50),
                    std::chrono::milliseconds(1000));
}

long long seconds_of(std::chrono::milliseconds ms) { return (ms.count() + 999) / 1000; }

}  // namespace

std::string peer_client(const std::string& peer) {
  std::string address = peer;
  if (const size_t colon = address.find(':');
      colon != std::string::npos &&
      (address.rfind("ipv4:", 0) == 0 || address.rfind("ipv6:", 0) == 0))
    address = address.substr(colon + 1);
  if (!address.empty() && address[0] == '[') {
    const size_t close = address.find(']');
    return close == std::string::npos ? address : address.substr(1, close - 1);
  }
  const size_t port = address.rfind(':');
  return port == std::string::npos ? address : address.substr(0, port);
}

StreamAdmission::StreamAdmission(StreamLimits limits)
    : limits_(limits), watchdog_([this] { watch_loop(); }) {}

StreamAdmission::~StreamAdmission() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  stop_changed_.notify_all();
  watchdog_.join();
}

size_t StreamAdmission::open_streams() const {
  std::lock_guard lock(mutex_);
  return admitted_;
}

void StreamAdmission::release(Entry& entry) {
  if (entry.expired) return;  // released when it expired
  --admitted_;
  if (const auto it = per_client_.find(entry.client); it != per_client_.end() && --it->second == 0)
    per_client_.erase(it);
}

std::unique_ptr<StreamAdmission::Ticket> StreamAdmission::admit(grpc::ServerContext* context,
                                                                const char* call,
                                                                grpc::Status* refused) {
  const std::string client = peer_client(context->peer());
  std::lock_guard lock(mutex_);
  unsigned& mine = per_client_[client];
  std::string why;
  if (admitted_ >= limits_.max_streams)
    why = "the coordinator has " + std::to_string(admitted_) + " streams open, its limit";
  else if (mine >= limits_.max_streams_per_client)
    why = "this client (" + client + ") has " + std::to_string(mine) +
          " streams open, the limit per client";
  if (!why.empty()) {
    if (mine == 0) per_client_.erase(client);
    context->AddTrailingMetadata("grpc-retry-pushback-ms", "1000");
    *refused = grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED,
                            std::string(call) + " refused: " + why +
                                "; retry in a second, or close streams you no longer read");
    spdlog::warn("{} from {} refused: {}", call, client, why);
    return nullptr;
  }
  ++mine;
  ++admitted_;
  const auto now = Clock::now();
  open_.push_front(Entry{context, call, client, now, now});
  return std::unique_ptr<Ticket>(new Ticket(*this, open_.begin()));
}

StreamAdmission::Ticket::~Ticket() {
  std::lock_guard lock(owner_.mutex_);
  owner_.release(*entry_);
  owner_.open_.erase(entry_);
}

void StreamAdmission::Ticket::touch() {
  std::lock_guard lock(owner_.mutex_);
  entry_->last_moved = Clock::now();
}

bool StreamAdmission::Ticket::past_total() const {
  std::lock_guard lock(owner_.mutex_);
  return Clock::now() - entry_->opened > owner_.limits_.total;
}

std::optional<grpc::Status> StreamAdmission::Ticket::expired() const {
  std::lock_guard lock(owner_.mutex_);
  if (!entry_->expired) return std::nullopt;
  const bool idle = std::string_view(entry_->expired) == "idle";
  return grpc::Status(
      grpc::StatusCode::DEADLINE_EXCEEDED,
      entry_->call +
          (idle ? " moved nothing for " + std::to_string(seconds_of(owner_.limits_.idle)) +
                      " s: closed"
                : " was open for more than " + std::to_string(seconds_of(owner_.limits_.total)) +
                      " s: closed (open it again to go on)"));
}

void StreamAdmission::watch_loop() {
  std::unique_lock lock(mutex_);
  while (!stop_changed_.wait_for(lock, scan_interval(limits_), [this] { return stopping_; })) {
    const auto now = Clock::now();
    for (Entry& entry : open_) {
      if (entry.expired) continue;
      const char* why = now - entry.last_moved > limits_.idle ? "idle"
                        : now - entry.opened > limits_.total  ? "open too long"
                                                              : nullptr;
      if (!why) continue;
      release(entry);
      entry.expired = why;
      spdlog::warn("{} from {}: {}, cancelled", entry.call, entry.client,
                   std::string_view(entry.expired) == "idle"
                       ? "moved nothing for " + std::to_string(seconds_of(limits_.idle)) + " s"
                       : "open for more than " + std::to_string(seconds_of(limits_.total)) + " s");
      entry.context->TryCancel();
    }
  }
}

}  // namespace parapm::rpc
