// Splits rows [0, rows) into contiguous blocks run on std::threads. The split depends only on the
// thread count, and callers write results per row, so sums formed afterwards are deterministic.
#pragma once

#include <algorithm>
#include <thread>
#include <vector>

namespace cbrdf::internal {

inline int thread_count(int requested, int rows) {
  int n = requested > 0 ? requested : int(std::thread::hardware_concurrency());
  return std::clamp(n, 1, std::max(rows, 1));
}

// fn(row_begin, row_end) for each block; the calling thread runs the first block itself.
template <typename Fn>
void parallel_rows(int rows, int threads, const Fn& fn) {
  const int n = thread_count(threads, rows);
  if (n <= 1) {
    fn(0, rows);
    return;
  }
  std::vector<std::thread> pool;
  pool.reserve(std::size_t(n - 1));
  for (int i = 1; i < n; ++i) {
    pool.emplace_back([&fn, i, n, rows] { fn(rows * i / n, rows * (i + 1) / n); });
  }
  fn(0, rows / n);
  for (std::thread& t : pool) t.join();
}

}  // namespace cbrdf::internal
