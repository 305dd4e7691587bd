// A view of consecutive points of a std::vector<Vec3<S>> (no copy): a cloud for every stage
// that reads clouds through CloudTraits. HOTS's sweep parts are such views into their frame's
// thinned points, which prepare_frames orders by part (hots/refine_prepare.hpp), so that the
// parts are not a second copy of the frames (docs/BENCHMARKS.md, "Long drives": memory).
//
// Conventions this header owns:
//   - A span does not own its points: the vector it views must outlive it and not reallocate.
//   - An empty span (count 0) may have a null `first`.
#pragma once

#include <cstddef>
#include <vector>

#include "ulc/core/point_traits.hpp"
#include "ulc/core/types.hpp"

namespace ulc {

template <typename S>
struct PointSpan {
  const Vec3<S>* first = nullptr;
  std::size_t count = 0;

  PointSpan() = default;
  PointSpan(const Vec3<S>* begin, std::size_t n) : first(begin), count(n) {}
  /// The whole of `points`.
  explicit PointSpan(const std::vector<Vec3<S>>& points)
      : first(points.data()), count(points.size()) {}

  const Vec3<S>* begin() const { return first; }
  const Vec3<S>* end() const { return first + count; }
  std::size_t size() const { return count; }
  bool empty() const { return count == 0; }
  const Vec3<S>& operator[](std::size_t i) const { return first[i]; }
};

template <typename S>
struct CloudTraits<PointSpan<S>> {
  using Cloud = PointSpan<S>;
  using Scalar = S;
  static std::size_t size(const Cloud& c) { return c.size(); }
  static Vec3<S> point(const Cloud& c, std::size_t i) { return c[i]; }
};

}  // namespace ulc
