// SPDX-License-Identifier: MIT
// The runner behind cbrdf/parallel.h: a persistent pool of std::threads shared by every loop, or
// the caller's runner.
//
// A loop is a Job on the pool's list. The thread that starts it claims tasks from an atomic
// counter like any helper, so it finishes the loop alone if no helper comes. Workers join a listed
// job while it wants helpers and has unclaimed tasks; when its tasks run out, the starting thread
// takes the job off the list (no helper joins after that) and waits for the helpers already in it.
#include "cbrdf/parallel.h"

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <exception>
#include <memory>
#include <mutex>
#include <system_error>
#include <thread>
#include <utility>
#include <vector>

#include "parallel_for.h"

namespace cbrdf {
namespace {

std::atomic<int> g_thread_limit{0};  // 0: one per hardware thread

// Set while this thread runs a task: loops started then run inline.
thread_local bool t_in_task = false;

class InTask {
 public:
  InTask() : was_(t_in_task) { t_in_task = true; }
  ~InTask() { t_in_task = was_; }
  InTask(const InTask&) = delete;
  InTask& operator=(const InTask&) = delete;

 private:
  bool was_;
};

// The first exception thrown by a loop's tasks; later tasks are skipped once one is recorded.
class FirstError {
 public:
  void record() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!error_) error_ = std::current_exception();
    failed_ = true;
  }
  bool failed() const { return failed_.load(std::memory_order_relaxed); }
  void rethrow() const {
    if (error_) std::rethrow_exception(error_);
  }

 private:
  std::mutex mutex_;
  std::exception_ptr error_;
  std::atomic<bool> failed_{false};
};

void run_task(const std::function<void(int)>& body, int task, FirstError* error) {
  if (error->failed()) return;
  const InTask in_task;
  try {
    body(task);
  } catch (...) {
    error->record();
  }
}

struct Job {
  Job(const std::function<void(int)>& b, int n, int helpers)
      : body(b), tasks(n), helpers_wanted(helpers) {}

  // Claims and runs tasks until none is left.
  void run() {
    for (int t = next.fetch_add(1); t < tasks; t = next.fetch_add(1)) run_task(body, t, &error);
  }
  bool has_unclaimed() const { return next.load() < tasks; }

  const std::function<void(int)>& body;
  const int tasks;
  const int helpers_wanted;
  std::atomic<int> next{0};
  FirstError error;
  // Guarded by the pool's mutex.
  int helpers_joined = 0;
  int helpers_active = 0;
  std::condition_variable helpers_done;
};

class Pool {
 public:
  Pool() = default;
  Pool(const Pool&) = delete;
  Pool& operator=(const Pool&) = delete;
  ~Pool() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    for (std::thread& t : workers_) t.join();
  }

  void run(int tasks, int threads, const std::function<void(int)>& body) {
    Job job(body, tasks, threads - 1);
    {
      std::lock_guard<std::mutex> lock(mutex_);
      grow(threads - 1);
      jobs_.push_back(&job);
    }
    wake_.notify_all();
    job.run();
    {
      std::unique_lock<std::mutex> lock(mutex_);
      jobs_.erase(std::find(jobs_.begin(), jobs_.end(), &job));
      job.helpers_done.wait(lock, [&] { return job.helpers_active == 0; });
    }
    job.error.rethrow();
  }

 private:
  // Called with mutex_ held. Workers live as long as the pool; a thread that cannot be made leaves
  // its share to the others and to the calling thread.
  void grow(int workers) {
    while (int(workers_.size()) < workers) {
      try {
        workers_.emplace_back([this] { work(); });
      } catch (const std::system_error&) {
        return;
      }
    }
  }

  Job* job_wanting_help() const {
    for (Job* job : jobs_) {
      if (job->helpers_joined < job->helpers_wanted && job->has_unclaimed()) return job;
    }
    return nullptr;
  }

  void work() {
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      Job* job = nullptr;
      wake_.wait(lock, [&] { return stop_ || (job = job_wanting_help()) != nullptr; });
      if (stop_) return;
      ++job->helpers_joined;
      ++job->helpers_active;
      lock.unlock();
      job->run();
      lock.lock();
      // Notified under the lock: the starting thread cannot return (and destroy the job) before
      // this thread has let go of it.
      if (--job->helpers_active == 0) job->helpers_done.notify_all();
    }
  }

  std::mutex mutex_;
  std::condition_variable wake_;
  std::vector<Job*> jobs_;
  std::vector<std::thread> workers_;
  bool stop_ = false;
};

Pool& pool() {
  static Pool p;
  return p;
}

std::mutex g_runner_mutex;
std::shared_ptr<const ParallelRunner> g_runner;

std::shared_ptr<const ParallelRunner> custom_runner() {
  std::lock_guard<std::mutex> lock(g_runner_mutex);
  return g_runner;
}

void run_on(const ParallelRunner& runner, int tasks, const std::function<void(int)>& body) {
  FirstError error;
  runner(tasks, [&](int task) { run_task(body, task, &error); });
  error.rethrow();
}

}  // namespace

void set_thread_limit(int n) {
  g_thread_limit = std::clamp(n, 0, kMaxThreadLimit);
}

int thread_limit() {
  const int n = g_thread_limit.load();
  if (n > 0) return n;
  return std::clamp(int(std::thread::hardware_concurrency()), 1, kMaxThreadLimit);
}

void set_parallel_runner(ParallelRunner runner) {
  auto next = runner ? std::make_shared<const ParallelRunner>(std::move(runner)) : nullptr;
  std::lock_guard<std::mutex> lock(g_runner_mutex);
  g_runner = std::move(next);
}

namespace internal {

int threads_for(int tasks, int max_threads) {
  if (t_in_task) return 1;
  const int limit = thread_limit();
  const int threads = max_threads > 0 ? std::min(max_threads, limit) : limit;
  return std::clamp(threads, 1, std::max(tasks, 1));
}

}  // namespace internal

void parallel_for(int tasks, int max_threads, const std::function<void(int)>& body) {
  const int threads = internal::threads_for(tasks, max_threads);
  if (threads <= 1) {
    for (int t = 0; t < tasks; ++t) body(t);
    return;
  }
  if (const auto runner = custom_runner()) {
    run_on(*runner, tasks, body);
    return;
  }
  pool().run(tasks, threads, body);
}

}  // namespace cbrdf
