// A float queue key as an unsigned integer of the same order: key_rank(x) < key_rank(y) exactly
// when x < y, for every key but NaN (-0 ranks as +0, its equal). A queue entry keeps the rank
// beside an end's id, so that its heap compares one 64-bit word, not a float and then an id,
// each with its own branch.
#pragma once

#include <bit>
#include <cstdint>

namespace parapm {

constexpr uint32_t key_rank(float key) {
  const uint32_t bits = std::bit_cast<uint32_t>(key + 0.0f);  // (-0 + 0 is +0)
  // Positive keys above every negative one; negative keys' order reversed.
  return bits & 0x80000000u ? ~bits : bits | 0x80000000u;
}

constexpr float rank_key(uint32_t rank) {
  return std::bit_cast<float>(rank & 0x80000000u ? rank & 0x7fffffffu : ~rank);
}

}  // namespace parapm
