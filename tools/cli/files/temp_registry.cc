// SPDX-License-Identifier: MIT
#include "files/temp_registry.h"

#include <limits.h>
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>

namespace cbrdf::cli::temp_registry {
namespace {

enum : int { kFree = 0, kClaimed = 1, kSet = 2 };

struct Slot {
  std::atomic<int> state{kFree};
  char path[PATH_MAX];
};

// More than enough for the writes one process has open at a time (the report writes a few files
// per thread).
constexpr int kSlots = 64;
Slot g_slots[kSlots];

static_assert(std::atomic<int>::is_always_lock_free, "the signal handler needs lock-free atomics");

// interrupt_sets(): the flag the next SIGINT sets instead of ending the process.
std::atomic<std::atomic<bool>*> g_interrupt{nullptr};
static_assert(std::atomic<std::atomic<bool>*>::is_always_lock_free);

void install(int sig);

void on_signal(int sig) {
  const int saved_errno = errno;
  if (sig == SIGINT) {
    if (std::atomic<bool>* flag = g_interrupt.exchange(nullptr)) {
      flag->store(true);
      install(SIGINT);  // SA_RESETHAND restored the default: a second SIGINT ends the process
      errno = saved_errno;
      return;
    }
  }
  unlink_all();
  errno = saved_errno;
  // SA_RESETHAND restored the default action; the signal is blocked until we return, then ends the
  // process as it would have without us.
  ::raise(sig);
}

// Async-signal-safe (sigaction is): on_signal reinstalls itself with it.
void install(int sig) {
  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESETHAND;
  (void)::sigaction(sig, &sa, nullptr);
}

}  // namespace

int add(const char* path) {
  const std::size_t n = std::strlen(path);
  if (n >= PATH_MAX) return -1;
  for (int i = 0; i < kSlots; ++i) {
    int expected = kFree;
    if (g_slots[i].state.compare_exchange_strong(expected, kClaimed, std::memory_order_acquire)) {
      std::memcpy(g_slots[i].path, path, n + 1);
      g_slots[i].state.store(kSet, std::memory_order_release);
      return i;
    }
  }
  return -1;
}

void remove(int slot) {
  if (slot >= 0 && slot < kSlots) g_slots[slot].state.store(kFree, std::memory_order_release);
}

void unlink_all() {
  for (Slot& s : g_slots) {
    if (s.state.load(std::memory_order_acquire) == kSet) ::unlink(s.path);
  }
}

void install_signal_handlers() {
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction old {};
    if (::sigaction(sig, nullptr, &old) != 0) continue;
    // A signal the caller ignores (nohup's SIGHUP) or handles stays as it is.
    if (old.sa_handler != SIG_DFL || (old.sa_flags & SA_SIGINFO)) continue;
    install(sig);
  }
}

void interrupt_sets(std::atomic<bool>* flag) {
  g_interrupt.store(flag);
}

}  // namespace cbrdf::cli::temp_registry
