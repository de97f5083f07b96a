// SPDX-License-Identifier: MIT
// EncoderSettings::progress inside the encoder: the thread that called the encoder calls the
// user's callback on a timer while the work runs on a thread of its own; the working threads only
// publish how far they are and poll a shared cancel flag at their checkpoints (a solver iteration,
// a HALS sweep, a task of a parallel loop, a file written or scored).
#pragma once

#include <atomic>
#include <functional>
#include <optional>
#include <utility>

#include "cbrdf/progress.h"
#include "cbrdf/status.h"

namespace cbrdf::internal {

// What an encode's threads share with the thread that calls the callback.
struct EncodeWatch {
  std::atomic<bool> cancel{false};
  std::atomic<double> fraction{0};
  std::atomic<const char*> stage{"fit"};  // a string literal
  // Raises the fraction (never lowers it: the callback's fraction is monotone).
  void advance(double f);
};

// The watch of the encode this thread works for; null outside a watched encode.
EncodeWatch* current_watch();

// Whether the encode this thread works for was cancelled (false outside a watched one). An atomic
// load: cheap enough for every solver iteration.
inline bool cancel_requested() {
  const EncodeWatch* w = current_watch();
  return w != nullptr && w->cancel.load(std::memory_order_relaxed);
}

// kCancelled, "cancelled".
Status cancelled_status();
// cancelled_status() once cancelled, else ok: CBRDF_RETURN_IF_ERROR(check_cancel()).
inline Status check_cancel() {
  return cancel_requested() ? cancelled_status() : ok_status();
}

// A part of the encode: [begin, end] of the enclosing part's share (of the whole encode at the
// top), named `stage` (a string literal, progress.h) while it runs. Parts nest on the thread
// doing the encode; ending a part reports it done.
class ProgressPart {
 public:
  ProgressPart(const char* stage, double begin, double end);
  ~ProgressPart();
  ProgressPart(const ProgressPart&) = delete;
  ProgressPart& operator=(const ProgressPart&) = delete;

  // `done` (0 to 1) of this part is done.
  void report(double done) const;

 private:
  EncodeWatch* watch_;
  double lo_ = 0, hi_ = 1;
  double outer_lo_ = 0, outer_hi_ = 1;
  const char* outer_stage_ = nullptr;
};

// parallel_for (parallel_for.h) for an encode: every task sees the encode's watch, tasks not yet
// started are skipped once it is cancelled, and finished tasks advance the current part.
void watched_parallel_for(int tasks, int max_threads, const std::function<void(int)>& body);

// Runs `work` as a watched encode. With a callback and no watched encode already running on this
// thread, the work runs on a thread of its own while this thread calls `callback` every
// kCallbackInterval until it ends; a false return sets the cancel flag, and the encode returns
// kCancelled once the work has stopped at its next checkpoint. Otherwise (no callback, or a
// nested call such as the rate control's encode_table) the work runs here, as part of the
// enclosing encode.
Status run_watched(const ProgressCallback& callback, const std::function<Status()>& work);

template <typename T, typename F>
Expected<T> watched(const ProgressCallback& callback, F&& work) {
  std::optional<Expected<T>> out;
  const Status s = run_watched(callback, [&]() -> Status {
    out.emplace(work());
    return out->ok() ? ok_status() : out->status();
  });
  if (!s.ok()) return s;
  return std::move(*out);
}

}  // namespace cbrdf::internal
