// cbrdf: the command-line front end. One file per subcommand; this file only dispatches.
#include <cstdio>

#include "cli.h"

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

int main(int argc, char** argv) {
  using namespace cbrdf::cli;
  CLI::App app{
      "cbrdf: a copula-based lossy codec for measured BRDFs (MERL .binary <-> .cbrdf)", "cbrdf"};
  app.set_version_flag("--version", CBRDF_VERSION_STRING);
  app.require_subcommand(1);
  app.fallthrough();  // -q and -v work after the subcommand too
  Context ctx;
  app.add_flag("-q,--quiet", ctx.quiet, "Print only errors");
  app.add_flag("-v,--verbose", ctx.verbose, "Print more detail");
  Action action;
  add_sample_command(app, ctx, &action);
  add_info_command(app, ctx, &action);
  add_encode_command(app, ctx, &action);
  add_decode_command(app, ctx, &action);
  add_report_command(app, ctx, &action);
  add_render_command(app, ctx, &action);
  add_imgdiff_command(app, ctx, &action);
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
