// SPDX-License-Identifier: MIT
// Shared pieces of the `cbrdf` command: exit codes, messages, subcommand registration.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <string>

#include "cbrdf/status.h"

namespace cbrdf::cli {

// Exit codes: 0 success, 1 bad input data (or a failed write), 2 bad usage.
inline constexpr int kExitOk = 0;
inline constexpr int kExitData = 1;
inline constexpr int kExitUsage = 2;
// Stopped by Ctrl-C (SIGINT), as a shell reports a process the signal ended (128 + 2).
inline constexpr int kExitInterrupted = 130;

struct Context {
  bool quiet = false;    // -q: only errors
  bool verbose = false;  // -v: extra detail
};

// The chosen subcommand's action, set by its parse callback.
using Action = std::function<int()>;

// One line on stderr, "cbrdf: MESSAGE", and exit code 1.
int fail(const Status& status);
// A usage error: one line on stderr and exit code 2.
int usage_error(const std::string& message);

// Each subcommand file registers itself: add_NAME_command for every line of subcommands.def.
#define CBRDF_SUBCOMMAND(name) \
  void add_##name##_command(CLI::App& app, const Context& ctx, Action* action);
#include "subcommands.def"
#undef CBRDF_SUBCOMMAND

}  // namespace cbrdf::cli
