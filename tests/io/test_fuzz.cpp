// Corrupted files: flipping or cutting bytes anywhere must give a cloud or an IoError, never a
// crash, a hang or another exception (deterministic seeds; run under ASan to check for reads
// out of bounds).
#include <catch2/catch.hpp>
#include <functional>
#include <random>

#include "io_test_util.hpp"
#include "ulc/io/kitti_bin.hpp"
#include "ulc/io/pcd.hpp"
#include "ulc/io/ply.hpp"

using io_test::Bytes;

namespace {

using Decoder = std::function<ulc::io::DecodedCloud(const Bytes&)>;

struct Outcome {
  std::size_t read = 0, rejected = 0;
};

/// Decodes `bytes`: returns true when read, false on IoError; anything else fails the test.
bool decodes(const Decoder& decode, const Bytes& bytes) {
  try {
    const auto cloud = decode(bytes);
    bool finite = true;
    for (const auto& p : cloud.points) finite = finite && p.allFinite();
    REQUIRE(finite);
    return true;
  } catch (const ulc::io::IoError& e) {
    REQUIRE(std::string(e.what()).find("fuzz.") == 0);
    return false;
  }
}

Outcome corrupt_everywhere(const Bytes& valid, const Decoder& decode, std::uint32_t seed) {
  Outcome out;
  REQUIRE(decodes(decode, valid));
  std::mt19937 rng(seed);
  auto count = [&](bool ok) { ++(ok ? out.read : out.rejected); };
  for (std::size_t pos = 0; pos < valid.size(); ++pos) {
    Bytes flipped = valid;
    flipped[pos] ^= static_cast<unsigned char>(1 + rng() % 255);
    count(decodes(decode, flipped));
    count(decodes(decode, Bytes(valid.begin(), valid.begin() + static_cast<std::ptrdiff_t>(pos))));
  }
  for (int trial = 0; trial < 300; ++trial) {  // several bytes at once, then a random cut
    Bytes bytes = valid;
    for (int k = 0; k < 4; ++k) bytes[rng() % bytes.size()] = static_cast<unsigned char>(rng());
    if (rng() % 2) bytes.resize(rng() % bytes.size());
    count(decodes(decode, bytes));
  }
  return out;
}

ulc::PointCloud<float> sample_cloud(std::size_t n) {
  const auto s = io_test::make_sample(n);
  ulc::PointCloud<float> c;
  c.points = s.points;
  c.intensities = s.intensities;
  c.times.assign(s.times.begin(), s.times.end());
  return c;
}

}  // namespace

TEST_CASE("fuzz: corrupted PCD binary_compressed never crashes", "[fuzz]") {
  const Bytes valid =
      ulc::io::encode_pcd(sample_cloud(150), ulc::io::PcdEncoding::binary_compressed);
  const Outcome o = corrupt_everywhere(
      valid, [](const Bytes& b) { return ulc::io::decode_pcd(b, "fuzz.pcd"); }, 1234);
  CHECK(o.rejected > 0);
  CHECK(o.read > 0);  // flips inside float payload still decode
}

TEST_CASE("fuzz: corrupted PCD binary and ascii never crash", "[fuzz]") {
  for (auto enc : {ulc::io::PcdEncoding::binary, ulc::io::PcdEncoding::ascii}) {
    const Bytes valid = ulc::io::encode_pcd(sample_cloud(40), enc);
    const Outcome o = corrupt_everywhere(
        valid, [](const Bytes& b) { return ulc::io::decode_pcd(b, "fuzz.pcd"); }, 99);
    CHECK(o.rejected > 0);
  }
}

TEST_CASE("fuzz: corrupted PLY and KITTI files never crash", "[fuzz]") {
  for (auto fmt : {ulc::io::PlyFormat::ascii, ulc::io::PlyFormat::binary_big_endian}) {
    const Bytes valid = ulc::io::encode_ply(sample_cloud(40), fmt);
    const Outcome o = corrupt_everywhere(
        valid, [](const Bytes& b) { return ulc::io::decode_ply(b, "fuzz.ply"); }, 5);
    CHECK(o.rejected > 0);
  }
  const Bytes kitti = ulc::io::encode_kitti_bin(sample_cloud(40));
  corrupt_everywhere(
      kitti, [](const Bytes& b) { return ulc::io::decode_kitti_bin(b, "fuzz.bin"); }, 6);
}
