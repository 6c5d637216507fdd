// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Progress hooks of the long CMGeom algorithms (Compact Model build and reconstruction, cage
// binding). The algorithms never print; a caller that wants to show progress puts a
// Progress_callback in the function's options, and the function calls it as it goes:
//   * with the fraction of the function's work done, in [0, 1], never decreasing from one call
//     to the next (a fraction is an estimate of the share of the running time, not a count of
//     elements: the phases of an algorithm are weighted by their measured cost);
//   * from the thread that called the function only, never from a TBB worker, so the hook needs
//     no lock and may touch what that thread owns (a terminal line, a GUI's state);
//   * at a bounded rate: at most about 256 times per phase of the work (an algorithm has a few
//     phases, each documented with the option that takes the hook), never per element; the last
//     call of a run that returns normally is 1.
// The hook must be cheap (it runs inside the algorithm's loops) and must not throw. An empty
// callback (the default) costs a test per block of work.
//
// internal::Progress_reporter is the algorithms' side: the phases and the counting, safe from
// parallel loops (workers only add to an atomic counter; the calling thread reports).
//
// Complexity: O(1) per reported block of work.
#ifndef CMGEOM_PROGRESS_H
#define CMGEOM_PROGRESS_H

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <functional>
#include <thread>

namespace CMGeom {

/// Progress hook: called with the fraction of the work done (see the file comment).
using Progress_callback = std::function<void(double fraction)>;

namespace internal {

/// Reports the progress of one run of an algorithm to a Progress_callback (which may be empty:
/// then every member does nothing). Construct it on the thread that calls the algorithm; the
/// work is cut into phases, each a part [begin, end] of the whole with a number of work units.
/// `add()` may be called from any thread; `phase()`, `report()` and `finish()` from the
/// constructing thread only.
class Progress_reporter {
public:
  explicit Progress_reporter(const Progress_callback& callback)
      : callback_(callback ? &callback : nullptr), owner_(std::this_thread::get_id()) {}
  Progress_reporter(const Progress_reporter&) = delete;
  Progress_reporter& operator=(const Progress_reporter&) = delete;

  bool active() const { return callback_ != nullptr; }

  /// Starts a phase covering [begin, end] of the whole, `work` units long (the previous phase
  /// ends where it is), and reports `begin`.
  void phase(double begin, double end, std::size_t work) {
    if (!callback_) return;
    begin_ = begin;
    end_ = std::max(begin, end);
    work_ = work;
    step_ = std::max<std::size_t>(1, work / 256);
    next_ = step_;
    done_.store(0, std::memory_order_relaxed);
    report(begin);
  }

  /// `n` more units of the current phase are done. From any thread: a worker only adds to the
  /// counter; the constructing thread reports when the count has passed the next 1/256 step.
  void add(std::size_t n) {
    if (!callback_) return;
    const std::size_t done = done_.fetch_add(n, std::memory_order_relaxed) + n;
    // next_ and the callback belong to the constructing thread: the id test comes first.
    if (std::this_thread::get_id() != owner_ || done < next_) return;
    next_ = done + step_;
    report(begin_ + (end_ - begin_) * std::min(1.0, double(done) / double(std::max<std::size_t>(work_, 1))));
  }

  /// Reports `fraction` of the whole when it is above the last one reported.
  void report(double fraction) {
    if (!callback_ || !(fraction > last_)) return;
    last_ = std::min(1.0, fraction);
    (*callback_)(last_);
  }

  /// The run is over: reports 1.
  void finish() { report(1.0); }

private:
  const Progress_callback* callback_;
  std::thread::id owner_;
  std::atomic<std::size_t> done_{0};
  std::size_t work_ = 0, step_ = 1, next_ = 1;
  double begin_ = 0, end_ = 0, last_ = -1;
};

}  // namespace internal
}  // namespace CMGeom

#endif  // CMGEOM_PROGRESS_H
