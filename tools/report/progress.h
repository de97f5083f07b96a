// SPDX-License-Identifier: MIT
// A progress bar on stderr for long reports: steps done, the running ones' share (from the
// encoder's progress callback), and a time estimate.
#pragma once

#include <atomic>
#include <chrono>
#include <cstddef>
#include <mutex>
#include <string>
#include <vector>

#include "cbrdf/progress.h"

namespace cbrdf::report {

class Progress {
 public:
  // `slots`: how many steps may run at once (one per material measured concurrently). Nothing is
  // printed when disabled (-q); the arithmetic is kept either way.
  Progress(std::size_t total_steps, bool enabled, std::size_t slots = 1);
  // Marks the step running in `slot` done; `what` names it. Safe to call from several threads.
  void step(std::size_t slot, const std::string& what);
  // The share (0..1) of the step running in `slot` that is done. A share below one reported before
  // in the same step is ignored, so the bar never moves backwards; a negative one (unknown) too.
  void partial(std::size_t slot, double share);
  // (steps done + the running steps' shares) / total, 0..1.
  double fraction() const;
  // An encoder callback for the step running in `slot`: the encode's fraction f becomes the share
  // from + f * (to - from) of the step (several encodes in one step each get their part). It
  // returns false (cancel) once *cancel is set, when `cancel` is not null.
  ProgressCallback callback(std::size_t slot, double from = 0, double to = 1,
                            const std::atomic<bool>* cancel = nullptr);
  // Clears the bar's line.
  void finish();
  std::size_t done() const;

 private:
  double fraction_locked() const;
  void draw(const std::string& what);
  mutable std::mutex mutex_;
  std::size_t total_;
  std::size_t done_ = 0;
  std::vector<double> partial_;  // per slot, the running step's share
  bool enabled_;
  bool drawn_ = false;
  std::string last_what_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  std::chrono::steady_clock::time_point last_draw_{};
};

// The part [from, to] of `whole`: a callback passing from + f * (to - from) on to it (a negative f,
// unknown, as is), for one of several encodes that make up one step. Empty when `whole` is.
ProgressCallback part_of(const ProgressCallback& whole, double from, double to);

}  // namespace cbrdf::report
