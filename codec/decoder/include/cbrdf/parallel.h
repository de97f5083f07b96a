// SPDX-License-Identifier: MIT
/// @file
/// How many threads cbrdf uses, and on what. Every parallel loop in the library (fitting, metrics,
/// sphere images, tabulating analytic BRDFs) and in the `cbrdf` command (rendering, the report)
/// runs through one runner, as libjxl's JxlParallelRunner does:
/// - the built-in runner is a pool of std::threads made on first use and reused; the calling thread
///   takes part, so a loop never waits for a thread that could not be made;
/// - set_thread_limit() is the one place a caller caps the threads (0: one per hardware thread);
///   per-call requests (FitSettings::threads, SphereSetup::threads, `--threads`, `--jobs`) take the
///   smaller of the request and the limit;
/// - set_parallel_runner() hands the loops to the caller's own scheduler (TBB, a game engine's job
///   system) instead.
/// Results never depend on the thread count or the runner: work is split into tasks that write
/// their own results, and sums are formed afterwards in a fixed order.
///
/// A loop started inside a task of another loop runs inline on that task's thread (no deadlock, no
/// oversubscription). A loop that may use one thread only (a request of 1, a limit of 1, a single
/// task, or a nested loop) runs inline on the calling thread and never reaches a custom runner.
///
/// Tasks should not throw. If one does, no further tasks are started, the running ones finish, and
/// the first exception is rethrown on the thread that started the loop; a custom runner never sees
/// an exception.
#pragma once

#include <functional>

namespace cbrdf {

/// The most threads any loop uses, including the calling thread: n >= 1 caps it at n (at most
/// kMaxThreadLimit), n <= 0 restores the default of one per hardware thread. Takes effect for loops
/// started afterwards; thread-safe.
void set_thread_limit(int n);
/// The limit in force, resolved: the value set, or the hardware thread count (at least 1).
[[nodiscard]] int thread_limit();
/// The largest limit set_thread_limit() accepts.
inline constexpr int kMaxThreadLimit = 256;

/// Runs body(task) exactly once for every task in [0, tasks), on any threads and in any order,
/// possibly concurrently, and returns when every call has returned. tasks >= 2.
using ParallelRunner = std::function<void(int tasks, const std::function<void(int task)>& body)>;

/// Replaces the built-in pool for loops started afterwards; nullptr restores it. Thread-safe; loops
/// already running finish on the runner they started with. The thread limit still decides how many
/// tasks some loops are split into, and a loop limited to one thread still runs inline.
void set_parallel_runner(ParallelRunner runner);

/// Runs body(task) for every task in [0, tasks) through the runner above, on at most
/// min(max_threads, thread_limit(), tasks) threads (max_threads <= 0: no cap of its own), and
/// returns when all have returned. The calling thread takes part. Tasks are handed out one at a
/// time, so uneven tasks balance; each task must write only its own results. Inside a task of
/// another loop it runs inline. The loop the library's own work uses, for a program's loops that
/// should share its threads (a renderer's rows, a batch of materials).
void parallel_for(int tasks, int max_threads, const std::function<void(int task)>& body);

}  // namespace cbrdf
