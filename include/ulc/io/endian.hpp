// Byte-order helpers for the binary formats.
//
// Values are assembled from bytes with shifts, so the code is correct on any host byte order;
// on the little-endian machines ULC runs on, compilers turn the little-endian loads into plain
// moves. Floating-point values travel as the integer of the same width (IEEE 754 assumed, as
// every supported platform has it). PCD and KITTI are little endian; PLY may be either.
#pragma once

#include <cstdint>
#include <cstring>
#include <type_traits>

namespace ulc::io {

enum class Endian { little, big };

namespace detail {

template <std::size_t N>
struct UintOfSize;
template <>
struct UintOfSize<1> {
  using type = std::uint8_t;
};
template <>
struct UintOfSize<2> {
  using type = std::uint16_t;
};
template <>
struct UintOfSize<4> {
  using type = std::uint32_t;
};
template <>
struct UintOfSize<8> {
  using type = std::uint64_t;
};

}  // namespace detail

/// Reads an arithmetic T stored with the given byte order at p (no alignment needed).
template <typename T>
T load(const unsigned char* p, Endian order) {
  static_assert(std::is_arithmetic_v<T>, "load<T>: T must be arithmetic");
  using U = typename detail::UintOfSize<sizeof(T)>::type;
  U u = 0;
  for (std::size_t k = 0; k < sizeof(T); ++k) {
    const std::size_t shift = order == Endian::little ? 8 * k : 8 * (sizeof(T) - 1 - k);
    u = static_cast<U>(u | static_cast<U>(static_cast<U>(p[k]) << shift));
  }
  T value;
  std::memcpy(&value, &u, sizeof(T));
  return value;
}

/// Writes an arithmetic T at p with the given byte order.
template <typename T>
void store(unsigned char* p, T value, Endian order) {
  static_assert(std::is_arithmetic_v<T>, "store<T>: T must be arithmetic");
  using U = typename detail::UintOfSize<sizeof(T)>::type;
  U u;
  std::memcpy(&u, &value, sizeof(T));
  for (std::size_t k = 0; k < sizeof(T); ++k) {
    const std::size_t shift = order == Endian::little ? 8 * k : 8 * (sizeof(T) - 1 - k);
    p[k] = static_cast<unsigned char>((u >> shift) & 0xffu);
  }
}

template <typename T>
T load_le(const unsigned char* p) {
  return load<T>(p, Endian::little);
}
template <typename T>
void store_le(unsigned char* p, T value) {
  store<T>(p, value, Endian::little);
}

}  // namespace ulc::io
