#include "call_admission.h"

#include <algorithm>

#include <spdlog/spdlog.h>

namespace parapm::rpc {
namespace {

using Clock = std::chrono::steady_clock;

// How often the watchdog looks: a small part of the idle limit.
std::chrono::milliseconds scan_interval(const CallLimits& limits) {
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

CallAdmission::CallAdmission(CallLimits limits)
    : limits_(limits), watchdog_([this] { watch_loop(); }) {}

CallAdmission::~CallAdmission() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  stop_changed_.notify_all();
  watchdog_.join();
}

void CallAdmission::release(Entry& entry) {
  if (entry.expired) return;  // released when it expired
  --admitted_;
  if (const auto it = per_client_.find(entry.client); it != per_client_.end() && --it->second == 0)
    per_client_.erase(it);
}

std::unique_ptr<CallAdmission::Ticket> CallAdmission::admit(grpc::ServerContext* context,
                                                            const char* call,
                                                            grpc::Status* refused) {
  const std::string client = peer_client(context->peer());
  std::lock_guard lock(mutex_);
  unsigned& mine = per_client_[client];
  std::string why;
  const std::string kind = limits_.kind;
  if (admitted_ >= limits_.max_calls)
    why = "the coordinator has " + std::to_string(admitted_) + " " + kind + " open, its limit";
  else if (mine >= limits_.max_per_client)
    why = "this client (" + client + ") has " + std::to_string(mine) + " " + kind +
          " open, the limit per client";
  if (!why.empty()) {
    if (mine == 0) per_client_.erase(client);
    context->AddTrailingMetadata("grpc-retry-pushback-ms", "1000");
    *refused = grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED,
                            std::string(call) + " refused: " + why +
                                "; retry in a second, or close " + kind + " you no longer read");
    spdlog::warn("{} from {} refused: {}", call, client, why);
    return nullptr;
  }
  ++mine;
  ++admitted_;
  const auto now = Clock::now();
  open_.push_front(Entry{context, call, client, now, now});
  return std::unique_ptr<Ticket>(new Ticket(*this, open_.begin()));
}

CallAdmission::Ticket::~Ticket() {
  std::lock_guard lock(owner_.mutex_);
  owner_.release(*entry_);
  owner_.open_.erase(entry_);
}

void CallAdmission::Ticket::touch() {
  std::lock_guard lock(owner_.mutex_);
  entry_->last_moved = Clock::now();
  entry_->working = false;
}

void CallAdmission::Ticket::working() {
  std::lock_guard lock(owner_.mutex_);
  entry_->working = true;
}

bool CallAdmission::Ticket::past_total() const {
  std::lock_guard lock(owner_.mutex_);
  return Clock::now() - entry_->opened > owner_.limits_.total;
}

std::optional<grpc::Status> CallAdmission::Ticket::expired() const {
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

void CallAdmission::watch_loop() {
  std::unique_lock lock(mutex_);
  while (!stop_changed_.wait_for(lock, scan_interval(limits_), [this] { return stopping_; })) {
    const auto now = Clock::now();
    for (Entry& entry : open_) {
      if (entry.expired) continue;
      const char* why = !entry.working && now - entry.last_moved > limits_.idle ? "idle"
                        : now - entry.opened > limits_.total                    ? "open too long"
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
