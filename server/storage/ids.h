// Identifiers and clock readings for stored records.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace parapm::service {

// `prefix` followed by 16 random lowercase hex characters (64 bits from std::random_device),
// e.g. new_id("job-") == "job-3f9a0c21d4e8b756". Unguessable enough that ids need no
// central counter and survive restarts without collisions. Thread-safe.
std::string new_id(std::string_view prefix);

// Wall-clock milliseconds since the Unix epoch (system_clock): stored timestamps are meant
// for people and for ordering records across restarts, not for measuring durations.
int64_t unix_ms_now();

}  // namespace parapm::service
