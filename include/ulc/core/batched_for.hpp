// parallel_for_in_batches: independent items run in parallel, in consecutive batches, with a
// hook called on the calling thread after each batch.
//
// Why: a caller's progress hook must run on the calling thread (Python checks Ctrl-C there, and
// only there), and a single parallel_for over a long phase gives it no chance until the phase
// ends (HOTS's hierarchies: tens of seconds on a 60 s drive). Batches of a few items per thread
// let the hook run every few items while the threads stay busy inside each batch; a hook that
// throws stops the loop after the current batch.
//
// The batches change nothing but when the hook runs: body(k) must be independent for every k
// (writing only its own slot), so results are the same for any batch size and thread count.
#pragma once

#include <algorithm>
#include <cstddef>
#include <functional>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

namespace ulc {

/// The fraction of a long step done, reported on the calling thread; it may throw to stop the
/// step (a Python hook raising KeyboardInterrupt).
using StepProgress = std::function<void(double fraction)>;

/// A part of a step as the whole step's progress: the part's own fraction f reported as
/// from + (to - from) f; empty when `progress` is.
inline StepProgress progress_within(const StepProgress& progress, double from, double to) {
  if (!progress) return {};
  return [progress, from, to](double f) { progress(from + (to - from) * f); };
}

/// Items per batch: a few per thread of the current arena, so a batch's last items keep only a
/// small share of the threads waiting.
inline std::size_t default_batch_size() {
  return 4 * static_cast<std::size_t>(std::max(tbb::this_task_arena::max_concurrency(), 1));
}

/// body(k) for k in [0, n), in parallel within batches of `batch` consecutive items; after each
/// batch, after_batch(items done so far) on the calling thread.
template <class Body, class AfterBatch>
void parallel_for_in_batches(std::size_t n, std::size_t batch, const Body& body,
                             const AfterBatch& after_batch) {
  batch = std::max<std::size_t>(batch, 1);
  for (std::size_t begin = 0; begin < n; begin += batch) {
    const std::size_t end = std::min(n, begin + batch);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(begin, end, 1),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t k = r.begin(); k != r.end(); ++k) body(k);
                      });
    after_batch(end);
  }
}

}  // namespace ulc
