// LZF (the liblzf format used by PCL's DATA binary_compressed): a checked decoder and a small
// greedy encoder, written for ULC.
//
// Stream format, a sequence of chunks, each starting with a control byte c:
//   c < 32    literal run: the next c + 1 input bytes are copied to the output.
//   c >= 32   back-reference: length L = c >> 5; L == 7 means L += next byte; the copy length is
//             L + 2. The byte after that (low) gives the distance d = ((c & 31) << 8 | low) + 1;
//             copy L + 2 bytes from d bytes back in the output, byte by byte (the source may
//             overlap the bytes being written, which repeats a short pattern).
// The decoder rejects every malformed stream with a status (reference before the start of the
// output, output beyond the capacity, input ending inside a chunk) and never reads or writes
// out of bounds. It does not throw: callers turn a status into IoError with their own context.
//
// Largest expansion: a 3-byte chunk can produce 7 + 255 + 2 = 264 bytes, so n input bytes
// decode to at most 88 * n bytes (kLzfMaxExpansion), a bound readers check before allocating.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

namespace ulc::io {

constexpr std::size_t kLzfMaxExpansion = 88;

enum class LzfStatus { ok, input_overrun, output_overflow, bad_reference };

struct LzfResult {
  LzfStatus status = LzfStatus::ok;
  std::size_t input_offset = 0;  ///< where decoding stopped (start of the failing chunk)
  std::size_t output_size = 0;   ///< bytes written

  bool ok() const { return status == LzfStatus::ok; }
  const char* message() const {
    switch (status) {
      case LzfStatus::ok:
        return "ok";
      case LzfStatus::input_overrun:
        return "LZF chunk runs past the end of the compressed data";
      case LzfStatus::output_overflow:
        return "LZF data decodes to more bytes than declared";
      case LzfStatus::bad_reference:
        return "LZF back-reference points before the start of the output";
    }
    return "unknown LZF status";
  }
};

/// Decodes in[0, in_size) into out[0, out_capacity).
inline LzfResult lzf_decompress(const unsigned char* in, std::size_t in_size, unsigned char* out,
                                std::size_t out_capacity) {
  std::size_t ip = 0;
  std::size_t op = 0;
  while (ip < in_size) {
    const std::size_t chunk = ip;
    const unsigned ctrl = in[ip++];
    if (ctrl < 32) {
      const std::size_t len = ctrl + 1u;
      if (len > in_size - ip) return {LzfStatus::input_overrun, chunk, op};
      if (len > out_capacity - op) return {LzfStatus::output_overflow, chunk, op};
      std::memcpy(out + op, in + ip, len);
      ip += len;
      op += len;
      continue;
    }
    std::size_t len = ctrl >> 5;
    if (len == 7) {
      if (ip >= in_size) return {LzfStatus::input_overrun, chunk, op};
      len += in[ip++];
    }
    len += 2;
    if (ip >= in_size) return {LzfStatus::input_overrun, chunk, op};
    const std::size_t distance = ((std::size_t{ctrl & 0x1fu} << 8) | in[ip++]) + 1;
    if (distance > op) return {LzfStatus::bad_reference, chunk, op};
    if (len > out_capacity - op) return {LzfStatus::output_overflow, chunk, op};
    // Byte by byte on purpose: an overlapping source must see the bytes just written.
    for (std::size_t k = 0; k < len; ++k, ++op) out[op] = out[op - distance];
  }
  return {LzfStatus::ok, ip, op};
}

namespace detail {

constexpr std::size_t kLzfMaxLiteral = 32;
constexpr std::size_t kLzfMaxMatch = 7 + 255 + 2;
constexpr std::size_t kLzfMaxDistance = 8192;
constexpr unsigned kLzfHashBits = 14;

inline void lzf_emit_literals(const unsigned char* begin, std::size_t n,
                              std::vector<unsigned char>& out) {
  while (n > 0) {
    const std::size_t run = n < kLzfMaxLiteral ? n : kLzfMaxLiteral;
    out.push_back(static_cast<unsigned char>(run - 1));
    out.insert(out.end(), begin, begin + run);
    begin += run;
    n -= run;
  }
}

inline std::uint32_t lzf_hash(const unsigned char* p) {
  const std::uint32_t v = (std::uint32_t{p[0]} << 16) | (std::uint32_t{p[1]} << 8) | p[2];
  return (v * 2654435761u) >> (32 - kLzfHashBits);
}

}  // namespace detail

/// Greedy LZF encoder: a hash of the next 3 bytes finds the last position with the same hash;
/// a verified match of 3+ bytes within 8 KiB becomes a back-reference, anything else a literal.
/// Not as tight as liblzf, but every output decodes with lzf_decompress to the input.
inline std::vector<unsigned char> lzf_compress(const unsigned char* in, std::size_t n) {
  using namespace detail;
  std::vector<unsigned char> out;
  out.reserve(n + n / kLzfMaxLiteral + 1);
  constexpr std::size_t kNone = static_cast<std::size_t>(-1);
  std::vector<std::size_t> last_seen(std::size_t{1} << kLzfHashBits, kNone);
  std::size_t literal_start = 0;
  std::size_t ip = 0;
  while (ip + 3 <= n) {
    const std::uint32_t h = lzf_hash(in + ip);
    const std::size_t ref = last_seen[h];
    last_seen[h] = ip;
    if (ref == kNone || ip - ref > kLzfMaxDistance || std::memcmp(in + ref, in + ip, 3) != 0) {
      ++ip;
      continue;
    }
    const std::size_t limit = n - ip < kLzfMaxMatch ? n - ip : kLzfMaxMatch;
    std::size_t len = 3;
    while (len < limit && in[ref + len] == in[ip + len]) ++len;
    lzf_emit_literals(in + literal_start, ip - literal_start, out);
    const std::size_t distance = ip - ref - 1;
    const std::size_t code = len - 2;
    if (code < 7) {
      out.push_back(static_cast<unsigned char>((code << 5) | (distance >> 8)));
    } else {
      out.push_back(static_cast<unsigned char>((7u << 5) | (distance >> 8)));
      out.push_back(static_cast<unsigned char>(code - 7));
    }
    out.push_back(static_cast<unsigned char>(distance & 0xffu));
    ip += len;
    literal_start = ip;
  }
  lzf_emit_literals(in + literal_start, n - literal_start, out);
  return out;
}

inline std::vector<unsigned char> lzf_compress(const std::vector<unsigned char>& in) {
  return lzf_compress(in.data(), in.size());
}

}  // namespace ulc::io
