// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Progress hooks of the long CMGeom algorithms (Compact Model build and reconstruction, cage
// binding): Progress_callback, and internal::Progress_reporter on the algorithms' side. The
// algorithms never print; a caller puts a callback in the function's options, and it is called
// with the fraction of the work done, never decreasing and ending at 1, from the calling thread
// only (TBB workers only count into an atomic), at most about 256 times per phase. The hook must
// be cheap and must not throw; an empty callback costs a test per block of work.
//
// Manual: doc/Concepts.md, "Conventions".
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
