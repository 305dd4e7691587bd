// deterministic_reduce: a parallel reduction whose result does not depend on the thread count.
//
// Why: floating-point addition is not associative, and tbb::parallel_reduce splits and joins
// ranges as work-stealing happens to go, so its sums change in the last bits between runs and
// between 1 and N threads. tbb::parallel_deterministic_reduce with a simple_partitioner always
// halves [0, n) down to chunks of at most `grain` items and joins them along that same fixed
// tree, whichever thread runs which chunk. So: same n and grain -> same bits, on any number of
// threads. Keep `grain` a constant (never derived from the thread count).
//
//   body(begin, end, acc) -> acc   folds items [begin, end) into acc (acc starts as identity)
//   join(left, right)     -> acc   combines two neighbouring partial results, left first
#pragma once

#include <algorithm>
#include <cstddef>
#include <utility>

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>
#include <tbb/partitioner.h>

namespace ulc {

constexpr std::size_t kDefaultReduceGrain = 1024;

template <class T, class Body, class Join>
T deterministic_reduce(std::size_t n, T identity, Body body, Join join,
                       std::size_t grain = kDefaultReduceGrain) {
  if (n == 0) return identity;
  const tbb::blocked_range<std::size_t> range(0, n, std::max<std::size_t>(grain, 1));
  return tbb::parallel_deterministic_reduce(
      range, identity,
      [&body](const tbb::blocked_range<std::size_t>& r, T acc) {
        return body(r.begin(), r.end(), std::move(acc));
      },
      [&join](T left, T right) { return join(std::move(left), std::move(right)); },
      tbb::simple_partitioner());
}

}  // namespace ulc
