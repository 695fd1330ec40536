// Errors raised by the engine. The engine never asserts on data it was given: a bad mesh, a
// cancelled job or a limit that was hit becomes an Error whose code says which, so that the
// service layer can map it to a transport status (INVALID_ARGUMENT, RESOURCE_EXHAUSTED, ...)
// in one place, and the CLI can print one clear line.
#pragma once

#include <stdexcept>
#include <string>

namespace parapm {

enum class ErrorCode {
  kInvalidInput,        // the data is malformed or violates a documented rule
  kResourceExhausted,   // a size limit was hit (declared counts, upload size, memory budget)
  kCancelled,           // the caller's cancellation token fired
  kDeadlineExceeded,    // the caller's deadline passed
  kNotFound,            // a file or object that was named does not exist
  kIo,                  // the operating system failed to read or write
  kFailedPrecondition,  // the object is not in the state the call needs (a job not done yet)
  kInternal,            // a bug: an invariant of the engine does not hold
  kDataLoss,            // stored bytes no longer match what was stored (a flipped byte, a cut file)
};

const char* error_code_name(ErrorCode code);

class Error : public std::runtime_error {
 public:
  Error(ErrorCode code, const std::string& message) : std::runtime_error(message), code_(code) {}
  ErrorCode code() const { return code_; }

 private:
  ErrorCode code_;
};

[[noreturn]] inline void throw_invalid(const std::string& message) {
  throw Error(ErrorCode::kInvalidInput, message);
}
[[noreturn]] inline void throw_internal(const std::string& message) {
  throw Error(ErrorCode::kInternal, message);
}

}  // namespace parapm
