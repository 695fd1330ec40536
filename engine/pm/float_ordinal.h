// Exact deltas between floating-point numbers, for the .pm file's split records.
//
// ordinal() maps the IEEE-754 bit pattern of a float (or double) to a signed integer that
// grows with the value: non-negative numbers keep their bit pattern, negative ones become
// ~(bits & magnitude_mask), i.e. -1 for -0.0, -2 for the next negative, ... The map is a
// bijection between all 2^32 (2^64) bit patterns and all int32 (int64) values, so NaN
// payloads, infinities and the sign of zero survive too.
//
// A delta is ordinal(a) - ordinal(b) computed modulo 2^32 (2^64) and read back as a signed
// integer: from_ordinal(ordinal(b) + delta) == a bit for bit, whatever a and b are, and the
// delta is small when a and b are close (a vertex that moves a little). No rounding is
// involved anywhere, which is what makes the stored splits, and undoing them, exact.
#pragma once

#include <bit>
#include <cstdint>

namespace parapm {

inline int32_t float_ordinal(float x) {
  const uint32_t bits = std::bit_cast<uint32_t>(x);
  return (bits >> 31) ? int32_t(~bits | 0x80000000u) : int32_t(bits);
}

inline float float_from_ordinal(int32_t ordinal) {
  const uint32_t bits = ordinal >= 0 ? uint32_t(ordinal) : (~uint32_t(ordinal) | 0x80000000u);
  return std::bit_cast<float>(bits);
}

inline int64_t double_ordinal(double x) {
  const uint64_t bits = std::bit_cast<uint64_t>(x);
  return (bits >> 63) ? int64_t(~bits | (uint64_t(1) << 63)) : int64_t(bits);
}

inline double double_from_ordinal(int64_t ordinal) {
  const uint64_t bits =
      ordinal >= 0 ? uint64_t(ordinal) : (~uint64_t(ordinal) | (uint64_t(1) << 63));
  return std::bit_cast<double>(bits);
}

// after - before, modulo 2^32, as a signed number.
inline int32_t float_delta(float after, float before) {
  return int32_t(uint32_t(float_ordinal(after)) - uint32_t(float_ordinal(before)));
}
inline float float_apply_delta(float before, int32_t delta) {
  return float_from_ordinal(int32_t(uint32_t(float_ordinal(before)) + uint32_t(delta)));
}

// after - before, modulo 2^64, as a signed number.
inline int64_t double_delta(double after, double before) {
  return int64_t(uint64_t(double_ordinal(after)) - uint64_t(double_ordinal(before)));
}
inline double double_apply_delta(double before, int64_t delta) {
  return double_from_ordinal(int64_t(uint64_t(double_ordinal(before)) + uint64_t(delta)));
}

}  // namespace parapm
