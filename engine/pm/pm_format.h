// Constants of the .pm binary format shared by its writer and reader; docs/PM-FORMAT.md is
// the specification, field by field.
#pragma once

#include <cstdint>

namespace parapm::pm_format {

// 0x89 first (catches 7-bit transfers), then the name, then '\n' (catches newline mangling).
inline constexpr char kMagic[8] = {'\x89', 'P', 'A', 'R', 'A', 'P', 'M', '\n'};
inline constexpr uint32_t kVersion = 1;

// Header flags.
inline constexpr uint32_t kFlagPositionsFloat64 = 1u << 0;  // else float32
inline constexpr uint32_t kFlagNormals = 1u << 1;
inline constexpr uint32_t kFlagTexcoords = 1u << 2;
inline constexpr uint32_t kFlagColors = 1u << 3;
inline constexpr uint32_t kFlagVertexCopies = 1u << 4;
inline constexpr uint32_t kFlagInputVertexOrder = 1u << 5;
inline constexpr uint32_t kFlagInputFaceOrder = 1u << 6;
inline constexpr uint32_t kKnownFlags = (1u << 7) - 1;

// Byte offsets of header fields (the fixed part is kFixedHeaderSize bytes, then the metric).
inline constexpr uint64_t kOffsetVersion = 8;
inline constexpr uint64_t kOffsetFlags = 12;
inline constexpr uint64_t kOffsetCounts = 16;
inline constexpr uint64_t kOffsetBox = 64;
inline constexpr uint64_t kOffsetMetricLength = 112;
inline constexpr uint64_t kFixedHeaderSize = 116;
inline constexpr uint32_t kMaxMetricLength = 255;

// The smallest split record: vs, vl + 1, vr + 1 (1 byte each), error (4), six deltas (1
// each); with attributes at least three corner codes and a change count more.
inline constexpr uint64_t kMinSplitBytes = 13;
inline constexpr uint64_t kMinSplitBytesWithAttributes = 17;

}  // namespace parapm::pm_format
