// Size limits of the recording readers. A length field larger than these is an error, never an
// allocation: a corrupted or hostile header claiming 2^40 bytes stops with a clear message.
#pragma once

#include <cstddef>
#include <cstdint>

namespace ulc::bags {

/// One record, chunk (compressed or not) or message: 1 GiB. ROS 1 writes 768 KiB chunks by
/// default, MCAP 4 MiB; a single 128-beam cloud is ~10 MB.
constexpr std::uint64_t kMaxRecordBytes = std::uint64_t{1} << 30;
/// One header field or string (topic, type, message definition): 16 MiB.
constexpr std::uint64_t kMaxStringBytes = std::uint64_t{1} << 24;
/// Elements of one array inside a message (points, fields): 2^28.
constexpr std::uint64_t kMaxArrayElements = std::uint64_t{1} << 28;

}  // namespace ulc::bags
