// ScalarType: the numeric types a PCD field or PLY property can have, and how to decode them.
//
// PCD spells a type as TYPE (I, U, F) plus SIZE (1, 2, 4, 8); PLY as a name (char, uchar, ...,
// or int8, uint8, ...). Both map onto this one enum; values are decoded to double, which is
// exact for every type except 64-bit integers beyond 2^53 (nanosecond stamps lose < 1 us).
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>

#include "ulc/io/endian.hpp"
#include "ulc/io/text_parse.hpp"

namespace ulc::io {

enum class ScalarType {
  int8,
  uint8,
  int16,
  uint16,
  int32,
  uint32,
  int64,
  uint64,
  float32,
  float64
};

inline std::size_t size_of(ScalarType t) {
  switch (t) {
    case ScalarType::int8:
    case ScalarType::uint8:
      return 1;
    case ScalarType::int16:
    case ScalarType::uint16:
      return 2;
    case ScalarType::int32:
    case ScalarType::uint32:
    case ScalarType::float32:
      return 4;
    case ScalarType::int64:
    case ScalarType::uint64:
    case ScalarType::float64:
      return 8;
  }
  return 0;
}

inline bool is_integer(ScalarType t) {
  return t != ScalarType::float32 && t != ScalarType::float64;
}

/// PCD TYPE letter and SIZE; nullopt for combinations PCD does not define (F1, F2, X4, ...).
inline std::optional<ScalarType> pcd_scalar_type(char type, std::size_t size) {
  if (type == 'I' || type == 'U') {
    const bool u = type == 'U';
    switch (size) {
      case 1:
        return u ? ScalarType::uint8 : ScalarType::int8;
      case 2:
        return u ? ScalarType::uint16 : ScalarType::int16;
      case 4:
        return u ? ScalarType::uint32 : ScalarType::int32;
      case 8:
        return u ? ScalarType::uint64 : ScalarType::int64;
      default:
        return std::nullopt;
    }
  }
  if (type == 'F' && size == 4) return ScalarType::float32;
  if (type == 'F' && size == 8) return ScalarType::float64;
  return std::nullopt;
}

/// PLY property type name (both the classic and the sized spelling).
inline std::optional<ScalarType> ply_scalar_type(std::string_view name) {
  struct Entry {
    std::string_view classic, sized;
    ScalarType type;
  };
  static constexpr Entry kTable[] = {
      {"char", "int8", ScalarType::int8},        {"uchar", "uint8", ScalarType::uint8},
      {"short", "int16", ScalarType::int16},     {"ushort", "uint16", ScalarType::uint16},
      {"int", "int32", ScalarType::int32},       {"uint", "uint32", ScalarType::uint32},
      {"float", "float32", ScalarType::float32}, {"double", "float64", ScalarType::float64},
  };
  for (const Entry& e : kTable)
    if (name == e.classic || name == e.sized) return e.type;
  return std::nullopt;
}

/// Decodes one value of type t stored at p with the given byte order.
inline double decode_scalar(const unsigned char* p, ScalarType t, Endian order) {
  switch (t) {
    case ScalarType::int8:
      return static_cast<double>(load<std::int8_t>(p, order));
    case ScalarType::uint8:
      return static_cast<double>(load<std::uint8_t>(p, order));
    case ScalarType::int16:
      return static_cast<double>(load<std::int16_t>(p, order));
    case ScalarType::uint16:
      return static_cast<double>(load<std::uint16_t>(p, order));
    case ScalarType::int32:
      return static_cast<double>(load<std::int32_t>(p, order));
    case ScalarType::uint32:
      return static_cast<double>(load<std::uint32_t>(p, order));
    case ScalarType::int64:
      return static_cast<double>(load<std::int64_t>(p, order));
    case ScalarType::uint64:
      return static_cast<double>(load<std::uint64_t>(p, order));
    case ScalarType::float32:
      return static_cast<double>(load<float>(p, order));
    case ScalarType::float64:
      return load<double>(p, order);
  }
  return 0.0;
}

/// Parses an ascii value of type t: float32 values are read as float, so the decimal text a
/// float32 writer produced comes back as exactly that float; every other type as double.
inline bool parse_value(std::string_view token, ScalarType t, double& value) {
  if (t != ScalarType::float32) return parse_double(token, value);
  float f = 0;
  if (!parse_float(token, f)) return false;
  value = static_cast<double>(f);
  return true;
}

}  // namespace ulc::io
