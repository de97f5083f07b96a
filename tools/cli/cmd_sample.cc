// SPDX-License-Identifier: MIT
// `cbrdf sample`: the built-in materials (measured and analytic), written as MERL tables.
#include <algorithm>
#include <cstdio>

#include "cbrdf/merl_io.h"
#include "cbrdf/samples.h"
#include "cli.h"
#include "cli_io.h"
#include "files/file_io.h"

namespace cbrdf::cli {
namespace {

struct SampleOptions {
  bool list = false;
  std::string name;
  std::string output;
};

int run_sample(const SampleOptions& o, const Context& ctx) {
  if (o.list) {
    for (const SampleInfo& s : sample_materials()) {
      std::printf("%-21s %-8s  %s\n", std::string(s.name).c_str(),
                  std::string(sample_kind_name(s.kind)).c_str(),
                  std::string(s.description).c_str());
    }
    return kExitOk;
  }
  if (o.name.empty()) return usage_error("sample: give a material NAME or --list");
  if (o.output.empty()) return usage_error("sample: give the output file with -o FILE.binary");
  const std::vector<PathArg> outputs = {{"-o", o.output}};
  if (auto bad = check_paths("sample", {}, outputs)) return usage_error(*bad);
  const auto known = sample_materials();
  const bool is_known = std::any_of(known.begin(), known.end(),
                                    [&](const SampleInfo& s) { return s.name == o.name; });
  auto table = make_sample(o.name);
  // An unknown name is a usage error (exit 2); the message lists the valid names.
  if (!table.ok() && !is_known) return usage_error("sample: " + table.status().message());
  if (!table.ok()) return fail(table.status());
  if (Status s = write_merl_output(output_path(o.output), *table); !s.ok()) return fail(s);
  if (!ctx.quiet)
    std::fprintf(info_stream(outputs), "wrote %s (%s)\n", shown(o.output, true).c_str(),
                 o.name.c_str());
  return kExitOk;
}

}  // namespace

void add_sample_command(CLI::App& app, const Context& ctx, Action* action) {
  auto o = std::make_shared<SampleOptions>();
  CLI::App* cmd = app.add_subcommand(
      "sample", "Write a built-in material (measured or analytic) as a MERL table");
  cmd->add_flag("--list", o->list, "List the built-in materials: name, kind, description");
  cmd->add_option("name", o->name, "Material name (see --list)");
  cmd->add_option("-o,--output", o->output, "Output MERL .binary file (- for standard output)");
  cmd->callback([o, &ctx, action] { *action = [o, &ctx] { return run_sample(*o, ctx); }; });
}

}  // namespace cbrdf::cli
