// SPDX-License-Identifier: MIT
// cbrdf view's HTTP server on 127.0.0.1: cpp-httplib parses requests and writes responses; the
// allowlist (view_allowlist.h) decides what is served and the connection loop
// (view_connections.h) bounds connections, threads, request size and idle time. GET and HEAD
// only, and only for a Host header naming this address (127.0.0.1:PORT or localhost:PORT,
// against DNS rebinding); files are streamed in 64 KiB pieces, never read whole.
#pragma once

#include <memory>

#include "cbrdf/status.h"
#include "view_allowlist.h"
#include "view_connections.h"

namespace cbrdf::cli {

class ViewServer {
 public:
  // Listens on 127.0.0.1:port (0: any free port). limits.max_connections is capped by the
  // file descriptors the process may open (RLIMIT_NOFILE, whose soft limit is raised as far as
  // the hard one allows).
  static Expected<std::unique_ptr<ViewServer>> listen(ViewAllowlist allowlist, int port,
                                                      ConnectionLimits limits = {});
  ~ViewServer();

  int port() const { return port_; }
  // Serves until request_stop(); an error when the server had to stop for another reason.
  Status run();
  // Async-signal-safe.
  void request_stop() noexcept;

  struct Impl;

 private:
  ViewServer() = default;
  std::unique_ptr<Impl> impl_;
  std::unique_ptr<ConnectionLoop> loop_;
  int port_ = 0;
};

}  // namespace cbrdf::cli
