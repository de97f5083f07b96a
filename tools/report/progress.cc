// SPDX-License-Identifier: MIT
#include "report/progress.h"

#include <algorithm>
#include <cstdio>

namespace cbrdf::report {

Progress::Progress(std::size_t total_steps, bool enabled)
    : total_(std::max<std::size_t>(total_steps, 1)), enabled_(enabled) {}

std::size_t Progress::done() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return done_;
}

void Progress::step(const std::string& what) {
  std::lock_guard<std::mutex> lock(mutex_);
  done_ = std::min(done_ + 1, total_);
  if (!enabled_) return;
  // Redraw at most ten times a second, and always for the last step.
  const auto now = std::chrono::steady_clock::now();
  if (done_ < total_ && now - last_draw_ < std::chrono::milliseconds(100)) return;
  last_draw_ = now;
  draw(what);
}

void Progress::draw(const std::string& what) {
  constexpr int kWidth = 30;
  const double fraction = double(done_) / double(total_);
  const int filled = int(fraction * kWidth);
  std::string bar(std::size_t(filled), '=');
  if (filled < kWidth) bar += '>';
  bar.resize(kWidth, ' ');
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  const double eta = done_ > 0 ? elapsed * double(total_ - done_) / double(done_) : 0.0;
  std::string name = what.substr(0, 36);
  std::fprintf(stderr, "\r[%s] %zu/%zu %3.0f%% %5.0fs left  %-36s", bar.c_str(), done_, total_,
               100.0 * fraction, eta, name.c_str());
  std::fflush(stderr);
  drawn_ = true;
}

void Progress::finish() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!enabled_ || !drawn_) return;
  std::fprintf(stderr, "\r%*s\r", 110, "");
  std::fflush(stderr);
  drawn_ = false;
}

}  // namespace cbrdf::report
