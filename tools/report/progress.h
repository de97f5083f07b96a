// SPDX-License-Identifier: MIT
// A progress bar on stderr for long reports: steps done, the current one, and a time estimate.
#pragma once

#include <chrono>
#include <cstddef>
#include <mutex>
#include <string>

namespace cbrdf::report {

class Progress {
 public:
  // Nothing is printed when disabled (-q).
  Progress(std::size_t total_steps, bool enabled);
  // Marks one step done; `what` names it. Safe to call from several threads.
  void step(const std::string& what);
  // Clears the bar's line.
  void finish();
  std::size_t done() const;

 private:
  void draw(const std::string& what);
  mutable std::mutex mutex_;
  std::size_t total_;
  std::size_t done_ = 0;
  bool enabled_;
  bool drawn_ = false;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  std::chrono::steady_clock::time_point last_draw_{};
};

}  // namespace cbrdf::report
