// Chunk compression of the recordings: bz2 and lz4 (ROS 1 bags), zstd and lz4 (MCAP).
//
// lz4 is the LZ4 frame format in both (ROS 1's roslz4 writes LZ4 frames). Decompression
// streams into `out`, growing it geometrically, and checks the result against the size the
// chunk's header claims: a header that lies makes an error, never a large allocation (the
// buffer only grows as far as the data really decompresses, and never past the claim).
#pragma once

#include <bzlib.h>
#include <lz4frame.h>
#include <zstd.h>

#include <algorithm>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "ulc/bags/limits.hpp"
#include "ulc/io/io_error.hpp"

namespace ulc::bags {

enum class Codec { none, bz2, lz4, zstd };

inline const char* codec_name(Codec c) {
  switch (c) {
    case Codec::none:
      return "none";
    case Codec::bz2:
      return "bz2";
    case Codec::lz4:
      return "lz4";
    case Codec::zstd:
      return "zstd";
  }
  return "?";
}

/// Where a compressed block sits, for error messages.
struct BlockPlace {
  const std::string& file;
  std::uint64_t offset;  ///< byte offset of the chunk record in the file
  [[noreturn]] void fail(const std::string& reason) const {
    throw io::IoError(file, io::at_byte(static_cast<std::size_t>(offset)), reason);
  }
};

namespace detail {

/// Grows `out` for the next stretch of output; fails once `expected` bytes are exceeded.
inline void grow_output(std::vector<unsigned char>& out, std::size_t used, std::uint64_t expected,
                        const BlockPlace& place, Codec codec) {
  if (used >= expected)
    place.fail(std::string(codec_name(codec)) + " chunk decompresses to more than the " +
               std::to_string(expected) + " bytes its header claims");
  const std::size_t next = std::max<std::size_t>(used * 2, 1 << 16);
  out.resize(static_cast<std::size_t>(std::min<std::uint64_t>(next, expected)));
}

inline void check_complete(std::size_t produced, std::uint64_t expected, bool finished,
                           const BlockPlace& place, Codec codec) {
  if (!finished)
    place.fail(std::string("truncated ") + codec_name(codec) + " chunk: the compressed data ends " +
               "before its end mark");
  if (produced != expected)
    place.fail(std::string(codec_name(codec)) + " chunk decompresses to " +
               std::to_string(produced) + " bytes, its header claims " + std::to_string(expected));
}

inline std::size_t first_capacity(std::size_t in_size, std::uint64_t expected) {
  const std::uint64_t guess = std::uint64_t{in_size} * 4 + (1 << 16);
  return static_cast<std::size_t>(std::min(guess, expected));
}

inline void decompress_bz2(const unsigned char* in, std::size_t n, std::uint64_t expected,
                           std::vector<unsigned char>& out, const BlockPlace& place) {
  bz_stream s{};
  if (BZ2_bzDecompressInit(&s, 0, 0) != BZ_OK) place.fail("cannot start bz2 decompression");
  std::unique_ptr<bz_stream, void (*)(bz_stream*)> guard(
      &s, [](bz_stream* p) { BZ2_bzDecompressEnd(p); });
  s.next_in = reinterpret_cast<char*>(const_cast<unsigned char*>(in));
  std::size_t in_left = n, used = 0;
  out.resize(first_capacity(n, expected));
  bool finished = false;
  while (!finished) {
    if (used == out.size()) grow_output(out, used, expected, place, Codec::bz2);
    const unsigned in_step = static_cast<unsigned>(std::min<std::size_t>(in_left, 1u << 30));
    const unsigned out_step =
        static_cast<unsigned>(std::min<std::size_t>(out.size() - used, 1u << 30));
    s.avail_in = in_step;
    s.next_out = reinterpret_cast<char*>(out.data() + used);
    s.avail_out = out_step;
    const int rc = BZ2_bzDecompress(&s);
    in_left -= in_step - s.avail_in;
    used += out_step - s.avail_out;
    if (rc == BZ_STREAM_END)
      finished = true;
    else if (rc != BZ_OK)
      place.fail("corrupted bz2 chunk (bzip2 error " + std::to_string(rc) + ")");
    else if (in_left == 0 && s.avail_out != 0)
      break;  // input used up without the end mark
  }
  check_complete(used, expected, finished, place, Codec::bz2);
  out.resize(used);
}

inline void decompress_lz4(const unsigned char* in, std::size_t n, std::uint64_t expected,
                           std::vector<unsigned char>& out, const BlockPlace& place) {
  LZ4F_dctx* ctx = nullptr;
  if (LZ4F_isError(LZ4F_createDecompressionContext(&ctx, LZ4F_VERSION)))
    place.fail("cannot start lz4 decompression");
  std::unique_ptr<LZ4F_dctx, LZ4F_errorCode_t (*)(LZ4F_dctx*)> guard(ctx,
                                                                     LZ4F_freeDecompressionContext);
  std::size_t in_pos = 0, used = 0;
  out.resize(first_capacity(n, expected));
  bool finished = false;
  while (!finished) {
    if (used == out.size()) grow_output(out, used, expected, place, Codec::lz4);
    std::size_t out_step = out.size() - used, in_step = n - in_pos;
    const std::size_t hint =
        LZ4F_decompress(ctx, out.data() + used, &out_step, in + in_pos, &in_step, nullptr);
    if (LZ4F_isError(hint))
      place.fail(std::string("corrupted lz4 chunk (") + LZ4F_getErrorName(hint) + ")");
    in_pos += in_step;
    used += out_step;
    if (hint == 0)
      finished = true;
    else if (in_pos == n && out_step == 0)
      break;  // input used up without the end mark
  }
  check_complete(used, expected, finished, place, Codec::lz4);
  out.resize(used);
}

inline void decompress_zstd(const unsigned char* in, std::size_t n, std::uint64_t expected,
                            std::vector<unsigned char>& out, const BlockPlace& place) {
  std::unique_ptr<ZSTD_DStream, std::size_t (*)(ZSTD_DStream*)> ctx(ZSTD_createDStream(),
                                                                    ZSTD_freeDStream);
  if (!ctx || ZSTD_isError(ZSTD_initDStream(ctx.get()))) place.fail("cannot start zstd");
  ZSTD_inBuffer src{in, n, 0};
  std::size_t used = 0;
  out.resize(first_capacity(n, expected));
  bool finished = false;
  while (!finished) {
    if (used == out.size()) grow_output(out, used, expected, place, Codec::zstd);
    ZSTD_outBuffer dst{out.data(), out.size(), used};
    const std::size_t rc = ZSTD_decompressStream(ctx.get(), &dst, &src);
    if (ZSTD_isError(rc))
      place.fail(std::string("corrupted zstd chunk (") + ZSTD_getErrorName(rc) + ")");
    const bool progressed = dst.pos != used;
    used = dst.pos;
    if (rc == 0)
      finished = true;
    else if (src.pos == src.size && !progressed && dst.pos < dst.size)
      break;
  }
  check_complete(used, expected, finished, place, Codec::zstd);
  out.resize(used);
}

}  // namespace detail

/// Decompresses `n` bytes into `out` (resized to `expected`, the size the chunk's header claims).
/// With Codec::none the bytes are copied. IoError at `place` for corrupted, truncated or
/// oversized data.
inline void decompress(Codec codec, const unsigned char* in, std::size_t n, std::uint64_t expected,
                       std::vector<unsigned char>& out, const BlockPlace& place) {
  if (expected > kMaxRecordBytes)
    place.fail("chunk claims " + std::to_string(expected) +
               " bytes uncompressed, more than the 1 GiB a chunk may hold");
  switch (codec) {
    case Codec::none:
      if (n != expected)
        place.fail("uncompressed chunk holds " + std::to_string(n) + " bytes, its header claims " +
                   std::to_string(expected));
      out.assign(in, in + n);
      return;
    case Codec::bz2:
      return detail::decompress_bz2(in, n, expected, out, place);
    case Codec::lz4:
      return detail::decompress_lz4(in, n, expected, out, place);
    case Codec::zstd:
      return detail::decompress_zstd(in, n, expected, out, place);
  }
}

/// Compresses for the writers (tests, benchmarks, `ulc` conversions). Throws std::runtime_error
/// only on a library failure (out of memory).
inline std::vector<unsigned char> compress(Codec codec, const unsigned char* in, std::size_t n) {
  std::vector<unsigned char> out;
  switch (codec) {
    case Codec::none:
      out.assign(in, in + n);
      break;
    case Codec::bz2: {
      unsigned int size = static_cast<unsigned int>(n + n / 100 + 601);
      out.resize(size);
      if (BZ2_bzBuffToBuffCompress(reinterpret_cast<char*>(out.data()), &size,
                                   reinterpret_cast<char*>(const_cast<unsigned char*>(in)),
                                   static_cast<unsigned int>(n), 9, 0, 0) != BZ_OK)
        throw std::runtime_error("bz2 compression failed");
      out.resize(size);
      break;
    }
    case Codec::lz4: {
      out.resize(LZ4F_compressFrameBound(n, nullptr));
      const std::size_t size = LZ4F_compressFrame(out.data(), out.size(), in, n, nullptr);
      if (LZ4F_isError(size)) throw std::runtime_error("lz4 compression failed");
      out.resize(size);
      break;
    }
    case Codec::zstd: {
      out.resize(ZSTD_compressBound(n));
      const std::size_t size = ZSTD_compress(out.data(), out.size(), in, n, 3);
      if (ZSTD_isError(size)) throw std::runtime_error("zstd compression failed");
      out.resize(size);
      break;
    }
  }
  return out;
}

}  // namespace ulc::bags
