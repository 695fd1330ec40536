// A pointer-based tokenizer over text already in memory, for the text formats (OBJ, ascii PLY,
// OFF, ascii STL): no copies, no locale, no iostreams. Numbers are parsed with std::from_chars
// (correctly rounded, so a float written in shortest form reads back bit for bit); "nan" and
// "inf" parse, out-of-range values become +-inf or 0 as strtod makes them.
//
// Whitespace is ' ', '\t', '\r', '\v', '\f' ("blanks") and '\n' (a new line, counted). Every
// read stays inside [begin, end): the buffer need not be NUL-terminated.
#pragma once

#include <algorithm>
#include <charconv>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string_view>
#include <system_error>
#include <type_traits>

namespace parapm::io {

inline bool is_blank(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}
inline bool is_separator(char c) { return is_blank(c) || c == '\n'; }

// Parses a number at [p, end) (an optional '+' is accepted). Returns the position after it,
// or nullptr when there is no number there. Does not check what follows.
template <class T>
const char* parse_number(const char* p, const char* end, T& value) {
  if (p < end && *p == '+') {
    ++p;
    if (p < end && *p == '-') return nullptr;  // "+-1"
  }
  const std::from_chars_result r = std::from_chars(p, end, value);
  if (r.ec == std::errc()) return r.ptr;
  if constexpr (std::is_floating_point_v<T>) {
    if (r.ec == std::errc::result_out_of_range) {
      // 1e999 or 1e-999: let strtod saturate to inf or flush to 0, on a NUL-terminated copy.
      char copy[128];
      const size_t n = std::min<size_t>(size_t(r.ptr - p), sizeof copy - 1);
      std::memcpy(copy, p, n);
      copy[n] = '\0';
      if constexpr (std::is_same_v<T, float>)
        value = std::strtof(copy, nullptr);
      else
        value = static_cast<T>(std::strtod(copy, nullptr));
      return r.ptr;
    }
  }
  return nullptr;
}

class TextScanner {
 public:
  TextScanner(const char* begin, const char* end, uint64_t first_line = 1)
      : p_(begin), end_(end), line_(first_line) {}
  explicit TextScanner(std::string_view text, uint64_t first_line = 1)
      : TextScanner(text.data(), text.data() + text.size(), first_line) {}

  const char* pos() const { return p_; }
  const char* end() const { return end_; }
  uint64_t line() const { return line_; }  // the line `pos` is on
  bool at_end() const { return p_ == end_; }
  size_t remaining() const { return size_t(end_ - p_); }

  // Skips blanks but not newlines.
  void skip_blanks() {
    while (p_ < end_ && is_blank(*p_)) ++p_;
  }
  // Skips all whitespace, newlines included.
  void skip_space() {
    while (p_ < end_) {
      if (*p_ == '\n')
        ++line_;
      else if (!is_blank(*p_))
        break;
      ++p_;
    }
  }
  // True at a newline or the end (call skip_blanks first to ignore trailing blanks).
  bool at_line_end() const { return p_ == end_ || *p_ == '\n'; }
  // Moves to the start of the next line (or the end).
  void next_line() {
    const void* nl = std::memchr(p_, '\n', size_t(end_ - p_));
    if (!nl) {
      p_ = end_;
    } else {
      p_ = static_cast<const char*>(nl) + 1;
      ++line_;
    }
  }
  // The rest of the current line from pos, without the newline and trailing blanks; no move.
  std::string_view rest_of_line() const {
    const void* nl = std::memchr(p_, '\n', size_t(end_ - p_));
    const char* e = nl ? static_cast<const char*>(nl) : end_;
    while (e > p_ && is_blank(e[-1])) --e;
    return {p_, size_t(e - p_)};
  }
  // The run of non-whitespace at pos (empty at whitespace or the end); moves past it.
  std::string_view token() {
    const char* b = p_;
    while (p_ < end_ && !is_separator(*p_)) ++p_;
    return {b, size_t(p_ - b)};
  }
  // Skips blanks, then reads a token; empty at the end of the line.
  std::string_view token_in_line() {
    skip_blanks();
    return token();
  }
  // Skips whitespace (newlines too), then reads a token; empty at the end of the text.
  std::string_view next_token() {
    skip_space();
    return token();
  }

  // Reads a number at pos that must end at whitespace or the end. False (pos unchanged) if
  // there is no such number.
  template <class T>
  bool read(T& value) {
    const char* after = parse_number(p_, end_, value);
    if (!after || (after < end_ && !is_separator(*after))) return false;
    p_ = after;
    return true;
  }
  // Like read(), but ending at `stop` is fine too (for OBJ's "1/2/3").
  template <class T>
  bool read_until(T& value, char stop) {
    const char* after = parse_number(p_, end_, value);
    if (!after || (after < end_ && !is_separator(*after) && *after != stop)) return false;
    p_ = after;
    return true;
  }

  bool consume(char c) {
    if (p_ < end_ && *p_ == c) {
      ++p_;
      return true;
    }
    return false;
  }
  char peek() const { return p_ < end_ ? *p_ : '\0'; }

 private:
  const char* p_;
  const char* end_;
  uint64_t line_;
};

// Case-insensitive comparison for ASCII keywords.
inline bool equals_ignore_case(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i) {
    char x = a[i], y = b[i];
    if (x >= 'A' && x <= 'Z') x = char(x - 'A' + 'a');
    if (y >= 'A' && y <= 'Z') y = char(y - 'A' + 'a');
    if (x != y) return false;
  }
  return true;
}

}  // namespace parapm::io
