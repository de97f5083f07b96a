// SPDX-License-Identifier: MIT
#include "encode_watch.h"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <thread>

#include "parallel_for.h"

namespace cbrdf::internal {
namespace {

// Well inside progress.h's promise of a call at least every 50 ms, with room for a slow callback.
constexpr auto kCallbackInterval = std::chrono::milliseconds(20);

thread_local EncodeWatch* t_watch = nullptr;
// The current part's share of the whole encode, on the thread doing the encode.
thread_local double t_lo = 0, t_hi = 1;

// Makes `watch` the one this thread works for, for the guard's life.
class WatchScope {
 public:
  WatchScope(EncodeWatch* watch, double lo, double hi) : watch_(t_watch), lo_(t_lo), hi_(t_hi) {
    t_watch = watch;
    t_lo = lo;
    t_hi = hi;
  }
  ~WatchScope() {
    t_watch = watch_;
    t_lo = lo_;
    t_hi = hi_;
  }
  WatchScope(const WatchScope&) = delete;
  WatchScope& operator=(const WatchScope&) = delete;

 private:
  EncodeWatch* watch_;
  double lo_, hi_;
};

}  // namespace

void EncodeWatch::advance(double f) {
  double seen = fraction.load(std::memory_order_relaxed);
  while (f > seen && !fraction.compare_exchange_weak(seen, f, std::memory_order_relaxed)) {
  }
}

EncodeWatch* current_watch() {
  return t_watch;
}

Status cancelled_status() {
  return error(ErrorCode::kCancelled, "cancelled");
}

ProgressPart::ProgressPart(const char* stage, double begin, double end) : watch_(t_watch) {
  if (watch_ == nullptr) return;
  outer_lo_ = t_lo;
  outer_hi_ = t_hi;
  lo_ = t_lo + begin * (t_hi - t_lo);
  hi_ = t_lo + end * (t_hi - t_lo);
  t_lo = lo_;
  t_hi = hi_;
  outer_stage_ = watch_->stage.exchange(stage, std::memory_order_relaxed);
  watch_->advance(lo_);
}

ProgressPart::~ProgressPart() {
  if (watch_ == nullptr) return;
  if (!watch_->cancel.load(std::memory_order_relaxed)) watch_->advance(hi_);
  t_lo = outer_lo_;
  t_hi = outer_hi_;
  watch_->stage.store(outer_stage_, std::memory_order_relaxed);
}

void ProgressPart::report(double done) const {
  if (watch_ != nullptr) watch_->advance(lo_ + std::clamp(done, 0.0, 1.0) * (hi_ - lo_));
}

void watched_parallel_for(int tasks, int max_threads, const std::function<void(int)>& body) {
  EncodeWatch* watch = t_watch;
  if (watch == nullptr) {
    parallel_for(tasks, max_threads, body);
    return;
  }
  const double lo = t_lo, hi = t_hi;
  std::atomic<int> finished{0};
  parallel_for(tasks, max_threads, [&](int task) {
    if (watch->cancel.load(std::memory_order_relaxed)) return;
    const WatchScope scope(watch, lo, hi);
    body(task);
    const int n = finished.fetch_add(1, std::memory_order_relaxed) + 1;
    watch->advance(lo + (hi - lo) * double(n) / double(tasks));
  });
}

Status run_watched(const ProgressCallback& callback, const std::function<Status()>& work) {
  if (t_watch != nullptr || !callback) return work();
  EncodeWatch watch;
  std::mutex mutex;
  std::condition_variable ended;
  bool done = false;
  Status status;
  std::exception_ptr failure;
  std::thread worker([&] {
    {
      const WatchScope scope(&watch, 0, 1);
      try {
        status = work();
      } catch (...) {
        failure = std::current_exception();
      }
    }
    std::lock_guard<std::mutex> lock(mutex);
    done = true;
    ended.notify_one();
  });
  std::exception_ptr callback_failure;
  {
    std::unique_lock<std::mutex> lock(mutex);
    while (!ended.wait_for(lock, kCallbackInterval, [&] { return done; })) {
      if (watch.cancel.load(std::memory_order_relaxed)) continue;
      lock.unlock();
      bool go_on = true;
      try {
        go_on = callback(EncodeProgress{watch.fraction.load(std::memory_order_relaxed),
                                        watch.stage.load(std::memory_order_relaxed)});
      } catch (...) {
        // Stop the work before passing the exception on: the worker must be joined first.
        callback_failure = std::current_exception();
        go_on = false;
      }
      if (!go_on) watch.cancel.store(true, std::memory_order_relaxed);
      lock.lock();
    }
  }
  worker.join();
  if (callback_failure) std::rethrow_exception(callback_failure);
  if (failure) std::rethrow_exception(failure);
  if (watch.cancel.load(std::memory_order_relaxed)) return cancelled_status();
  return status;
}

}  // namespace cbrdf::internal
