// SPDX-License-Identifier: MIT
// A replaced global operator new/delete that meters the heap, for the tests that bound memory
// (resource_bounds_test, model_eval_test). Include it in exactly one file of a test binary: it
// defines the replacement operators.
#pragma once

#include <malloc.h>

#include <atomic>
#include <cstdlib>
#include <new>

namespace cbrdf::testing::heap {

inline std::atomic<std::size_t> live{0};     // bytes held through operator new
inline std::atomic<std::size_t> peak{0};     // the most `live` has been since the meter started
inline std::atomic<std::size_t> largest{0};  // the largest single request since then

// Heap use of the code between start() and the read-outs, relative to what was live at start().
struct Meter {
  std::size_t baseline = 0;
  void start() {
    baseline = live.load();
    peak = baseline;
    largest = 0;
  }
  std::size_t peak_bytes() const { return peak.load() - baseline; }
  std::size_t largest_bytes() const { return largest.load(); }
};

}  // namespace cbrdf::testing::heap

// The deletes are replaced too, so that new and delete pair as malloc and free even under ASan.
// GCC cannot see that this operator new is malloc and warns about the pairing.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void* operator new(std::size_t n) {
  namespace heap = cbrdf::testing::heap;
  void* p = std::malloc(n == 0 ? 1 : n);
  if (!p) throw std::bad_alloc();
  const std::size_t now = heap::live.fetch_add(malloc_usable_size(p)) + malloc_usable_size(p);
  std::size_t peak = heap::peak.load();
  while (now > peak && !heap::peak.compare_exchange_weak(peak, now)) {
  }
  std::size_t largest = heap::largest.load();
  while (n > largest && !heap::largest.compare_exchange_weak(largest, n)) {
  }
  return p;
}
void* operator new[](std::size_t n) {
  return operator new(n);
}
void operator delete(void* p) noexcept {
  if (p) cbrdf::testing::heap::live.fetch_sub(malloc_usable_size(p));
  std::free(p);
}
void operator delete[](void* p) noexcept {
  operator delete(p);
}
void operator delete(void* p, std::size_t) noexcept {
  operator delete(p);
}
void operator delete[](void* p, std::size_t) noexcept {
  operator delete(p);
}
