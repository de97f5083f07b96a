// SPDX-License-Identifier: MIT
#include "report/progress.h"

#include <algorithm>
#include <cstdio>
#include <numeric>

namespace cbrdf::report {

Progress::Progress(std::size_t total_steps, bool enabled, std::size_t slots)
    : total_(std::max<std::size_t>(total_steps, 1)),
      partial_(std::max<std::size_t>(slots, 1), 0.0),
      enabled_(enabled) {}

std::size_t Progress::done() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return done_;
}

double Progress::fraction() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return fraction_locked();
}

double Progress::fraction_locked() const {
  const double running = std::accumulate(partial_.begin(), partial_.end(), 0.0);
  return std::min(1.0, (double(done_) + running) / double(total_));
}

void Progress::step(std::size_t slot, const std::string& what) {
  std::lock_guard<std::mutex> lock(mutex_);
  done_ = std::min(done_ + 1, total_);
  partial_.at(slot) = 0;
  last_what_ = what;
  if (!enabled_) return;
  // Redraw at most ten times a second, and always for the last step.
  const auto now = std::chrono::steady_clock::now();
  if (done_ < total_ && now - last_draw_ < std::chrono::milliseconds(100)) return;
  last_draw_ = now;
  draw(what);
}

void Progress::partial(std::size_t slot, double share) {
  std::lock_guard<std::mutex> lock(mutex_);
  double& p = partial_.at(slot);
  // Below one, so that a step counts whole only once step() marks it done.
  share = std::min(share, 0.999);
  if (!(share > p)) return;
  p = share;
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  if (now - last_draw_ < std::chrono::milliseconds(100)) return;
  last_draw_ = now;
  draw(last_what_);
}

ProgressCallback Progress::callback(std::size_t slot, double from, double to,
                                    const std::atomic<bool>* cancel) {
  return part_of(
      [this, slot, cancel](const EncodeProgress& p) {
        partial(slot, p.fraction);
        return cancel == nullptr || !cancel->load();
      },
      from, to);
}

ProgressCallback part_of(const ProgressCallback& whole, double from, double to) {
  if (!whole) return {};
  return [whole, from, to](const EncodeProgress& p) {
    if (p.fraction < 0) return whole(p);
    const double f = std::clamp(p.fraction, 0.0, 1.0);
    return whole(EncodeProgress{from + f * (to - from), p.stage});
  };
}

void Progress::draw(const std::string& what) {
  constexpr int kWidth = 30;
  const double fraction = fraction_locked();
  const int filled = int(fraction * kWidth);
  std::string bar(std::size_t(filled), '=');
  if (filled < kWidth) bar += '>';
  bar.resize(kWidth, ' ');
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  const double eta = fraction > 0 ? elapsed * (1 - fraction) / fraction : 0.0;
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
