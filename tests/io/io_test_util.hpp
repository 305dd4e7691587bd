// Helpers for the I/O tests: temporary folders, byte builders, IoError checks, sample clouds.
#pragma once

#include <unistd.h>

#include <Eigen/Core>
#include <atomic>
#include <catch2/catch.hpp>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <string>
#include <vector>

#include "../support/temp_dir.hpp"
#include "ulc/core/cloud.hpp"
#include "ulc/io/io_error.hpp"

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__,
              "the I/O tests build little-endian bytes with memcpy");

namespace io_test {

namespace fs = std::filesystem;
using Bytes = std::vector<unsigned char>;

/// A fresh folder under the system temp dir (tests/support/temp_dir.hpp).
struct TempDir : ulc_test::TempDir {
  TempDir() : ulc_test::TempDir("ulc_io_test") {}
};

/// Appends raw values (host = little endian) or text.
struct ByteBuilder {
  Bytes bytes;
  template <typename T>
  ByteBuilder& put(T v) {
    unsigned char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    bytes.insert(bytes.end(), b, b + sizeof(T));
    return *this;
  }
  /// Big-endian variant, for PLY binary_big_endian.
  template <typename T>
  ByteBuilder& put_be(T v) {
    unsigned char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    bytes.insert(bytes.end(), std::make_reverse_iterator(b + sizeof(T)),
                 std::make_reverse_iterator(b));
    return *this;
  }
  ByteBuilder& text(const std::string& s) {
    bytes.insert(bytes.end(), s.begin(), s.end());
    return *this;
  }
  ByteBuilder& raw(const Bytes& b) {
    bytes.insert(bytes.end(), b.begin(), b.end());
    return *this;
  }
};

inline Bytes to_bytes(const std::string& s) {
  return Bytes(s.begin(), s.end());
}

inline void write_bytes(const fs::path& path, const Bytes& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
}
inline void write_text(const fs::path& path, const std::string& text) {
  write_bytes(path, to_bytes(text));
}

/// LZF stream made only of literal runs: valid LZF built without our encoder.
inline Bytes lzf_literals_only(const Bytes& data) {
  Bytes out;
  for (std::size_t i = 0; i < data.size(); i += 32) {
    const std::size_t n = std::min<std::size_t>(32, data.size() - i);
    out.push_back(static_cast<unsigned char>(n - 1));
    out.insert(out.end(), data.begin() + static_cast<std::ptrdiff_t>(i),
               data.begin() + static_cast<std::ptrdiff_t>(i + n));
  }
  return out;
}

/// Runs f, requires an IoError whose what() contains every one of `parts`; returns it.
inline ulc::io::IoError require_io_error(const std::function<void()>& f,
                                         std::initializer_list<std::string> parts) {
  try {
    f();
  } catch (const ulc::io::IoError& e) {
    const std::string what = e.what();
    INFO("what(): " << what);
    for (const std::string& p : parts) CHECK(what.find(p) != std::string::npos);
    return e;
  }
  FAIL("expected an IoError containing " << *parts.begin());
  throw std::logic_error("unreachable");
}

/// Deterministic float-exact sample data: points, intensities, relative times.
struct Sample {
  std::vector<Eigen::Vector3f> points;
  std::vector<float> intensities;
  std::vector<float> times;
};

inline Sample make_sample(std::size_t n) {
  Sample s;
  std::uint32_t state = 12345;
  auto next = [&]() {
    state = state * 1664525u + 1013904223u;
    return static_cast<float>(state >> 8) / static_cast<float>(1u << 24);  // [0, 1)
  };
  for (std::size_t i = 0; i < n; ++i) {
    s.points.emplace_back(next() * 200.f - 100.f, next() * 200.f - 100.f, next() * 20.f - 5.f);
    s.intensities.push_back(next() * 255.f);
    s.times.push_back(static_cast<float>(i) * 1e-5f + next() * 1e-6f);
  }
  return s;
}

/// A user point type with every optional field (float), as a user might declare it.
struct UserPoint {
  float x, y, z;
  float intensity;
  float t;
};

/// A points-only user type.
struct PlainPoint {
  double x, y, z;
};

}  // namespace io_test
