// SPDX-License-Identifier: MIT
// cbrdf view's connections: one thread polls the listening socket and every idle connection, and
// hands a connection to a bounded pool of workers only when a request has started to arrive, so
// that idle connections (a browser's spares, or a flood of them) hold a file descriptor but no
// thread. Every limit is explicit: connections (the oldest idle one is closed to admit a new one
// at the cap; when accept() runs out of file descriptors below it, the cap drops to leave a few
// spare for the files requests open), threads, request head bytes, idle
// time, and the time a read or write may make no progress. HTTP itself is cpp-httplib's: a
// worker runs the ServeOne callback over the connection's httplib::Stream.
#pragma once

#include <httplib.h>

#include <chrono>
#include <cstddef>
#include <functional>
#include <memory>

#include "cbrdf/status.h"

namespace cbrdf::cli {

struct ConnectionLimits {
  std::size_t threads = 32;                       // workers serving requests at once
  std::size_t max_connections = 512;              // open connections, idle or served
  std::chrono::milliseconds idle_timeout{15000};  // an idle connection is closed after this
  std::chrono::milliseconds io_timeout{10000};    // a request head must arrive, and each write
                                                  // make progress, within this
  std::size_t max_request_bytes = 65536;          // request line and headers
  std::size_t max_requests_per_connection = 100;  // then the connection is closed
};

// Serves one request read from the stream (the connection's last when `last`: the response says
// so); returns whether the connection may stay open.
using ServeOne = std::function<bool(httplib::Stream& stream, bool last)>;

class ConnectionLoop {
 public:
  // Takes the listening socket (listening, non-blocking) and closes it when destroyed.
  static Expected<std::unique_ptr<ConnectionLoop>> create(int listen_fd, ConnectionLimits limits,
                                                          ServeOne serve);
  ~ConnectionLoop();
  ConnectionLoop(const ConnectionLoop&) = delete;
  ConnectionLoop& operator=(const ConnectionLoop&) = delete;

  // Serves until request_stop(), then waits for the workers. An error only when the listening
  // socket itself fails (never for a client's error or for running out of file descriptors).
  Status run();
  // Async-signal-safe: a signal handler may call it.
  void request_stop() noexcept;
  bool stopping() const noexcept;

  struct State;

 private:
  explicit ConnectionLoop(std::unique_ptr<State> state);
  std::unique_ptr<State> s_;
};

// RLIMIT_NOFILE's soft limit raised towards the hard limit (to at most `wanted`), and the number of
// connections that leaves room for, with `reserve` descriptors kept for the files being served.
std::size_t connection_capacity(std::size_t wanted, std::size_t reserve);

}  // namespace cbrdf::cli
