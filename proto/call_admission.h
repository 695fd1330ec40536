// Admission control for the calls of clients, each of which holds a server thread for as long
// as it runs (the sync API): a bound on calls in progress in all and per client, so that idle
// or greedy clients cannot take the threads the workers' registrations and heartbeats need;
// and a watchdog that cancels a call that moved no message for `idle` or has run for `total`,
// so that a stream a client abandons without closing frees its thread. The coordinator keeps
// one for streaming calls and one for unary calls (server/main.cpp).
//
// A refused call gets RESOURCE_EXHAUSTED saying which bound was hit, with the trailing
// metadata grpc-retry-pushback-ms (when to retry). Thread-safe.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <list>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include <grpcpp/grpcpp.h>

namespace parapm::rpc {

struct CallLimits {
  const char* kind = "streams";  // in messages: "streams", "calls"
  unsigned max_calls = 64;       // calls in progress, all clients together
  unsigned max_per_client = 16;  // per client address (its IP, without the port)
  std::chrono::milliseconds idle{std::chrono::seconds(60)};  // no message moved: cancelled
  std::chrono::milliseconds total{std::chrono::hours(1)};    // open this long: cancelled
};

class CallAdmission {
  struct Entry;

 public:
  explicit CallAdmission(CallLimits limits);  // starts the watchdog thread
  ~CallAdmission();
  CallAdmission(const CallAdmission&) = delete;
  CallAdmission& operator=(const CallAdmission&) = delete;

  // An admitted call; leaving its handler (destroying the ticket) frees its place.
  class Ticket {
   public:
    ~Ticket();
    Ticket(const Ticket&) = delete;
    Ticket& operator=(const Ticket&) = delete;
    void touch();  // a message moved: the idle clock starts again
    // The server works on the call (parsing an upload, loading a PM, cutting a level), not
    // waiting for the client: the idle limit does not apply until the next touch().
    void working();
    bool past_total() const;  // open for longer than the total limit
    // The status to end with once the watchdog cancelled the call (idle or past the total),
    // else nullopt.
    std::optional<grpc::Status> expired() const;

   private:
    friend class CallAdmission;
    Ticket(CallAdmission& owner, std::list<Entry>::iterator entry) : owner_(owner), entry_(entry) {}
    CallAdmission& owner_;
    std::list<Entry>::iterator entry_;
  };

  // Admits the call named `call` of `context`, or returns nullptr and sets *refused.
  std::unique_ptr<Ticket> admit(grpc::ServerContext* context, const char* call,
                                grpc::Status* refused);

 private:
  struct Entry {
    grpc::ServerContext* context;
    std::string call, client;
    std::chrono::steady_clock::time_point opened, last_moved;
    const char* expired = nullptr;  // "idle" or "open too long" once cancelled
    bool working = false;           // Ticket::working() since the last touch()
  };
  // Gives back the place of an admitted call (once: at expiry or at the ticket's end).
  void release(Entry& entry);
  void watch_loop();

  CallLimits limits_;
  mutable std::mutex mutex_;
  std::condition_variable stop_changed_;
  bool stopping_ = false;
  std::list<Entry> open_;  // admitted calls whose handlers are still running
  size_t admitted_ = 0;    // those of open_ not expired: an expired one is on its way out
  std::map<std::string, unsigned> per_client_;  // admitted, per client
  std::thread watchdog_;
};

// The client part of a peer string: "ipv4:127.0.0.1:5000" -> "127.0.0.1",
// "ipv6:[::1]:5000" -> "::1".
std::string peer_client(const std::string& peer);

}  // namespace parapm::rpc
