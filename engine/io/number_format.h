// Shortest round-trip decimal text for the writers: std::to_chars gives the shortest string
// that reads back (with from_chars or strtod) to the same double or float, bit for bit.
#pragma once

#include <charconv>
#include <cstdint>
#include <string>

namespace parapm::io {

template <class T>
inline void append_number(std::string& out, T value) {
  char buf[64];
  const std::to_chars_result r = std::to_chars(buf, buf + sizeof buf, value);
  out.append(buf, static_cast<size_t>(r.ptr - buf));
}

}  // namespace parapm::io
