// SPDX-License-Identifier: MIT
// cbrdf: the command-line front end. One file per subcommand; this file only dispatches.
#include <cstdio>
#include <cstring>
#include <exception>
#include <new>
#include <string>

#include "cbrdf/version.h"
#include "cli.h"
#include "files/file_io.h"

namespace cbrdf::cli {

int fail(const Status& status) {
  std::fprintf(stderr, "cbrdf: %s\n", status.message().c_str());
  return kExitData;
}

int usage_error(const std::string& message) {
  std::fprintf(stderr, "cbrdf: %s (see --help)\n", message.c_str());
  return kExitUsage;
}

}  // namespace cbrdf::cli

namespace {

using namespace cbrdf::cli;

struct Subcommand {
  const char* name;
  void (*add)(CLI::App& app, const Context& ctx, Action* action);
};

constexpr Subcommand kSubcommands[] = {
#define CBRDF_SUBCOMMAND(name) {#name, add_##name##_command},
#include "subcommands.def"
#undef CBRDF_SUBCOMMAND
};

// CLI11 says "A subcommand is required" for a mistyped one; name it instead. Global options are
// flags only, so the first argument that is not an option is the subcommand.
int check_subcommand(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    const char* a = argv[i];
    if (a[0] == '-') continue;
    for (const Subcommand& s : kSubcommands) {
      if (std::strcmp(a, s.name) == 0) return kExitOk;
    }
    std::string list;
    for (const Subcommand& s : kSubcommands) list += std::string(list.empty() ? "" : ", ") + s.name;
    return usage_error(std::string("unknown subcommand '") + a + "' (" + list + ")");
  }
  return kExitOk;
}

int run(int argc, char** argv) {
  CLI::App app{"cbrdf: a copula-based lossy codec for measured BRDFs (MERL .binary <-> .cbrdf)",
               "cbrdf"};
  app.set_version_flag("--version", CBRDF_VERSION_STRING);
  app.require_subcommand(1);
  app.fallthrough();  // -q and -v work after the subcommand too
  Context ctx;
  app.add_flag("-q,--quiet", ctx.quiet, "Print only errors");
  app.add_flag("-v,--verbose", ctx.verbose, "Print more detail");
  Action action;
  for (const Subcommand& s : kSubcommands) s.add(app, ctx, &action);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    return usage_error(e.what());
  }
  return action ? action() : kExitUsage;
}

}  // namespace

int main(int argc, char** argv) {
  // Interrupted writes leave no temporary files behind (file_io.h).
  cbrdf::cli::remove_temporaries_on_signals();
  if (int code = check_subcommand(argc, argv); code != kExitOk) return code;
  // The library reports errors as values; this is the last resort for what escapes anyway (a
  // third-party library's exception, memory exhaustion), so that no input ends in an abort.
  try {
    return run(argc, argv);
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "cbrdf: out of memory\n");
  } catch (const std::exception& e) {
    std::string what = e.what();
    for (char& c : what) c = c == '\n' || c == '\r' ? ' ' : c;  // one line
    std::fprintf(stderr, "cbrdf: internal error: %s\n", what.c_str());
  } catch (...) {
    std::fprintf(stderr, "cbrdf: internal error: unknown exception\n");
  }
  return kExitData;
}
