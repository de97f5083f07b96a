// SPDX-License-Identifier: MIT
// The library's loops over the runner of cbrdf/parallel.h: the row and chunk splits its own
// loops use. Not installed and not part of the API; programs use cbrdf::parallel_for.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <functional>

#include "cbrdf/parallel.h"

namespace cbrdf::internal {

// The threads a loop of `tasks` tasks may use: min(max_threads, thread_limit(), tasks), where
// max_threads <= 0 means no request of its own; 1 inside a task of another loop. At least 1.
[[nodiscard]] int threads_for(int tasks, int max_threads);

// The public loop (cbrdf/parallel.h), under the name the library's loops use.
using cbrdf::parallel_for;

// Splits rows [0, rows) into threads_for(rows, max_threads) contiguous blocks and calls
// fn(row_begin, row_end) once per block. The split depends only on the thread count, and callers
// write results per row, so sums formed afterwards are deterministic.
template <typename Fn>
void parallel_rows(int rows, int max_threads, const Fn& fn) {
  const int blocks = threads_for(rows, max_threads);
  if (blocks <= 1) {
    fn(0, rows);
    return;
  }
  parallel_for(blocks, blocks, [&](int b) {
    const auto row = [&](int i) { return int(std::int64_t(rows) * i / blocks); };
    fn(row(b), row(b + 1));
  });
}

// Splits items [0, n) into chunks of about `chunk` items (batches of direction pairs, draws) and
// calls fn(begin, end) once per chunk on the pool; one chunk runs on the calling thread.
template <typename Fn>
void parallel_chunks(std::size_t n, std::size_t chunk, int max_threads, const Fn& fn) {
  if (n == 0) return;
  const std::size_t chunks = (n + chunk - 1) / chunk;
  if (chunks == 1) {
    fn(std::size_t(0), n);
    return;
  }
  const int tasks = int(std::min<std::size_t>(chunks, 1 << 20));
  const std::size_t per = (n + std::size_t(tasks) - 1) / std::size_t(tasks);
  parallel_for(tasks, max_threads, [&](int t) {
    const std::size_t b = std::size_t(t) * per;
    if (b < n) fn(b, std::min(n, b + per));
  });
}

}  // namespace cbrdf::internal
