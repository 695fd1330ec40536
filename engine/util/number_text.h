// A double as the shortest text that reads back to it ("0.1", "1e+308", "nan"): for messages,
// where std::to_string would print 1e308 as 309 digits and 1e-9 as "0.000000".
#pragma once

#include <charconv>
#include <string>

namespace parapm {

inline std::string number_text(double value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  return std::string(buffer, result.ptr);
}

}  // namespace parapm
