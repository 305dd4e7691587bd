// Voxel keys and a deterministic voxel map.
//
// Conventions this header owns:
//   - A point p falls in voxel floor(p / size) per axis, computed in double, so voxel 0 covers
//     [0, size) and -0.05 with size 0.1 is voxel -1 (not 0, as truncation would give).
//   - Keys are three int32. A key is only made when every floor(p / size) fits in int32 and p
//     is finite; otherwise make_voxel_key() returns nullopt. So NaN, Inf and far-away points
//     (1e12 m with 0.1 m voxels) are rejected without undefined behaviour, and callers can
//     count them instead of allocating voxels for them.
//   - VoxelMap iterates in insertion order, never in hash order: anything computed by walking
//     it is the same on every run, platform and standard library.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include "ulc/core/types.hpp"

namespace ulc {

struct VoxelKey {
  std::int32_t x = 0, y = 0, z = 0;

  friend bool operator==(const VoxelKey& a, const VoxelKey& b) {
    return a.x == b.x && a.y == b.y && a.z == b.z;
  }
  friend bool operator!=(const VoxelKey& a, const VoxelKey& b) { return !(a == b); }
  /// Lexicographic (x, y, z): for sorting keys.
  friend bool operator<(const VoxelKey& a, const VoxelKey& b) {
    if (a.x != b.x) return a.x < b.x;
    if (a.y != b.y) return a.y < b.y;
    return a.z < b.z;
  }
};

/// Hash: the three coordinates are folded into 64 bits with distinct odd multipliers and then
/// passed through the splitmix64 finaliser (full avalanche: every input bit flips each output
/// bit with probability ~1/2). The classic `x*p1 ^ y*p2 ^ z*p3` spatial hash leaves the low
/// bits of neighbouring voxels correlated, which piles regular LiDAR grids into few buckets.
struct VoxelKeyHash {
  std::size_t operator()(const VoxelKey& k) const {
    std::uint64_t h = static_cast<std::uint32_t>(k.x);
    h = h * 0x9E3779B97F4A7C15ULL + static_cast<std::uint32_t>(k.y);
    h = h * 0xC2B2AE3D27D4EB4FULL + static_cast<std::uint32_t>(k.z);
    h ^= h >> 30;
    h *= 0xBF58476D1CE4E5B9ULL;
    h ^= h >> 27;
    h *= 0x94D049BB133111EBULL;
    h ^= h >> 31;
    return static_cast<std::size_t>(h);
  }
};

/// floor(v / size) as int32, or nullopt when it is not finite or does not fit.
inline std::optional<std::int32_t> voxel_coordinate(double v, double size) {
  const double q = std::floor(v / size);
  // Written so that NaN fails the test (every comparison with NaN is false).
  if (!(q >= -2147483648.0 && q <= 2147483647.0)) return std::nullopt;
  return static_cast<std::int32_t>(q);
}

/// The voxel of p for a voxel edge `size` (> 0, finite), or nullopt (see the header comment).
template <typename S>
std::optional<VoxelKey> make_voxel_key(const Vec3<S>& p, double size) {
  if (!(size > 0.0) || !std::isfinite(size)) return std::nullopt;
  const auto x = voxel_coordinate(static_cast<double>(p.x()), size);
  const auto y = voxel_coordinate(static_cast<double>(p.y()), size);
  const auto z = voxel_coordinate(static_cast<double>(p.z()), size);
  if (!x || !y || !z) return std::nullopt;
  return VoxelKey{*x, *y, *z};
}

/// The lower corner of a voxel (its centre is corner + size/2 per axis).
inline Vec3<double> voxel_corner(const VoxelKey& k, double size) {
  return Vec3<double>(k.x * size, k.y * size, k.z * size);
}

/// Key -> Value map that remembers insertion order. Entries sit in one vector (iteration,
/// index access); an open-addressing table of positions (linear probing, load <= 1/2, no
/// allocation per key) translates keys to positions. Entries are never erased, so positions stay
/// valid for the map's lifetime (pointers to values do not: the vector grows).
template <typename Value>
class VoxelMap {
 public:
  struct Entry {
    VoxelKey key;
    Value value;
  };

  std::size_t size() const { return entries_.size(); }
  bool empty() const { return entries_.empty(); }
  void reserve(std::size_t n) {
    entries_.reserve(n);
    if (2 * n > slots_.size()) rehash(table_size_for(n));
  }
  void clear() {
    entries_.clear();
    slots_.clear();
  }

  /// Position of key in insertion order, or nullopt.
  std::optional<std::size_t> position(const VoxelKey& key) const {
    if (slots_.empty()) return std::nullopt;
    const std::size_t slot = slots_[find_slot(key)];
    if (slot == kEmpty) return std::nullopt;
    return slot - 1;
  }
  bool contains(const VoxelKey& key) const { return position(key).has_value(); }

  Value* find(const VoxelKey& key) {
    const auto pos = position(key);
    return pos ? &entries_[*pos].value : nullptr;
  }
  const Value* find(const VoxelKey& key) const {
    const auto pos = position(key);
    return pos ? &entries_[*pos].value : nullptr;
  }

  /// The position of key, inserting Value(args...) at the end when absent; .second is true
  /// when it was inserted.
  template <typename... Args>
  std::pair<std::size_t, bool> try_emplace(const VoxelKey& key, Args&&... args) {
    if (2 * (entries_.size() + 1) > slots_.size()) rehash(table_size_for(entries_.size() + 1));
    std::size_t& slot = slots_[find_slot(key)];
    if (slot != kEmpty) return {slot - 1, false};
    entries_.push_back(Entry{key, Value(std::forward<Args>(args)...)});
    slot = entries_.size();  // position + 1
    return {entries_.size() - 1, true};
  }

  /// The value of key, default-constructed and appended when absent.
  Value& operator[](const VoxelKey& key) { return entries_[try_emplace(key).first].value; }

  Entry& at_position(std::size_t i) { return entries_[i]; }
  const Entry& at_position(std::size_t i) const { return entries_[i]; }

  auto begin() { return entries_.begin(); }
  auto end() { return entries_.end(); }
  auto begin() const { return entries_.begin(); }
  auto end() const { return entries_.end(); }

 private:
  static constexpr std::size_t kEmpty = 0;  ///< slots hold position + 1

  /// Smallest power of two >= 2 n (and >= 16).
  static std::size_t table_size_for(std::size_t n) {
    std::size_t size = 16;
    while (size < 2 * n) size *= 2;
    return size;
  }

  /// The slot holding key, or the empty slot where it belongs. The table is never full.
  std::size_t find_slot(const VoxelKey& key) const {
    const std::size_t mask = slots_.size() - 1;
    std::size_t i = VoxelKeyHash()(key) & mask;
    while (slots_[i] != kEmpty && entries_[slots_[i] - 1].key != key) i = (i + 1) & mask;
    return i;
  }

  void rehash(std::size_t new_size) {
    slots_.assign(new_size, kEmpty);
    const std::size_t mask = new_size - 1;
    for (std::size_t pos = 0; pos < entries_.size(); ++pos) {
      std::size_t i = VoxelKeyHash()(entries_[pos].key) & mask;
      while (slots_[i] != kEmpty) i = (i + 1) & mask;
      slots_[i] = pos + 1;
    }
  }

  std::vector<Entry> entries_;
  std::vector<std::size_t> slots_;
};

}  // namespace ulc
